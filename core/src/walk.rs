//! Rays walking through the scene: the one loop that crosses null boundaries and tracks the
//! medium a ray travels in ([`RayWalk`], used by every integrator and by the photon pass), and
//! the one camera walk to the first non-delta surface ([`walk_to_diffuse`], used by `photon`,
//! `sppm` and `vpm`).
//!
//! **Null boundaries.** A surface with the `null` material (the boundary of a volume of fog)
//! does not scatter: a ray crosses it, takes the medium on its other side, and goes on from
//! an origin pushed off the surface. The piece of medium between the boundary and that origin
//! (the *gap*) is part of the next segment: a segment is measured from the boundary, so free
//! flights and transmittance cover the whole medium.
//!
//! **The crossing limit.** A ray may cross at most [`MAX_NULL_CROSSINGS`] null boundaries in a
//! row (between two scattering events). Past that it is ended and carries nothing further: a
//! loss of energy, which only a ray trapped among hundreds of coincident boundaries can meet.
//! Shadow rays through media follow the same rule (`Scene::transmittance`: zero past the
//! limit); without media a shadow ray is one BVH traversal that passes every null boundary,
//! with no loop to limit.

use crate::Rgb;
use crate::bsdf::Bsdf;
use crate::direct::{Mis, Scatter, estimate_direct};
use crate::error::Result;
use crate::geometry::{Hit, Ray, offset_origin};
use crate::light::Light;
use crate::material::TransportMode;
use crate::medium::Medium;
use crate::props::Properties;
use crate::sampling::{Sampler, power_heuristic};
use crate::scene::Scene;
use glam::Vec3;

/// Null boundaries a ray may cross in a row before it is ended (see the module comment).
pub const MAX_NULL_CROSSINGS: u32 = 256;

/// A ray on its way through the scene: where it is, the medium it travels in, and the null
/// boundaries it has crossed since it last scattered.
#[derive(Clone, Copy, Debug)]
pub struct RayWalk {
    pub ray: Ray,
    /// The medium the ray travels in (None: vacuum).
    pub medium: Option<u32>,
    /// How far the ray's origin lies past the null boundary it just crossed, along the ray.
    gap: f32,
    crossings: u32,
    /// Emitting surfaces are passed through, as null boundaries are, until the ray first
    /// scatters: a camera ray with `hide_emitters` (Mitsuba's: directly seen emitters are
    /// skipped, what lies behind them is seen).
    skip_emitters: bool,
}

/// What a walk's ray met at the end of a segment ([`RayWalk::reach`]).
#[derive(Clone, Copy, Debug)]
pub enum Reached {
    /// A surface that scatters, with its BSDF there.
    Surface(Bsdf),
    /// A null boundary, crossed: trace the next segment.
    Crossed,
    /// A null boundary past the crossing limit: the ray is ended.
    Ended,
}

/// The piece of a walk's ray from its start (its origin, or the null boundary it just
/// crossed) to the next surface, null or not.
#[derive(Clone, Copy, Debug)]
pub struct Segment {
    /// The ray as traced (its origin may lie `gap` past the boundary it crossed).
    pub ray: Ray,
    /// The medium along the segment (None: vacuum).
    pub medium: Option<u32>,
    /// The surface that ends it; None: the ray leaves the scene.
    pub hit: Option<Hit>,
    gap: f32,
}

impl Segment {
    /// The segment's length from its start: to the surface, or infinite.
    #[inline]
    pub fn length(&self) -> f32 {
        self.hit.map_or(f32::INFINITY, |h| h.t + self.gap)
    }

    /// The point at distance `t` from the segment's start.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.ray.at(t - self.gap)
    }

    /// The ray from the segment's start (what [`Medium`] queries take).
    #[inline]
    pub fn start(&self) -> Ray {
        Ray::new(self.ray.at(-self.gap), self.ray.dir)
    }

    /// The radiance the surface that ends the segment emits back along the ray, with its
    /// light and the light's index; None if it emits none that way (or there is no surface).
    #[inline]
    pub fn emitted<'a>(&self, scene: &'a Scene) -> Option<(u32, &'a Light, Rgb)> {
        let hit = self.hit.as_ref()?;
        let (id, light) = scene.area_light(hit)?;
        let uv = if light.needs_uv() {
            scene.surface(hit).uv
        } else {
            glam::Vec2::ZERO
        };
        let le = light.emitted(hit.ng, uv, -self.ray.dir);
        (le != Rgb::ZERO).then_some((id, light, le))
    }

    /// The segment's medium, if it absorbs or scatters (a vacuum medium is skipped, so that it
    /// renders exactly as no medium).
    #[inline]
    pub fn interacting_medium<'a>(&self, scene: &'a Scene) -> Option<&'a dyn Medium> {
        let m = scene.medium(self.medium?);
        (!m.is_vacuum()).then_some(m)
    }
}

impl RayWalk {
    pub fn new(ray: Ray, medium: Option<u32>) -> Self {
        RayWalk {
            ray,
            medium,
            gap: 0.0,
            crossings: 0,
            skip_emitters: false,
        }
    }

    /// A camera ray's walk: from the camera's medium, passing through emitters until it first
    /// scatters if the scene hides them (`[render] hide_emitters`).
    pub fn camera(scene: &Scene, ray: Ray) -> Self {
        RayWalk {
            skip_emitters: scene.render.hide_emitters,
            ..RayWalk::new(ray, scene.camera_medium)
        }
    }

    /// Traces the ray to the next surface (null boundaries included); adds the ray to `rays`.
    #[inline]
    pub fn segment(&mut self, scene: &Scene, rays: &mut u64) -> Segment {
        *rays += 1;
        Segment {
            ray: self.ray,
            medium: self.medium,
            hit: scene.intersect(&self.ray, f32::INFINITY),
            gap: std::mem::take(&mut self.gap),
        }
    }

    /// Crosses the null boundary at `hit` (the end of the last segment) into the medium on its
    /// other side. False past [`MAX_NULL_CROSSINGS`] crossings in a row: the ray is ended.
    #[inline]
    pub fn cross(&mut self, scene: &Scene, hit: &Hit) -> bool {
        self.crossings += 1;
        if self.crossings > MAX_NULL_CROSSINGS {
            return false;
        }
        let dir = self.ray.dir;
        self.medium = scene.medium_after(hit, dir, self.medium);
        let origin = offset_origin(hit.p, hit.ng, dir);
        // The origin is offset along the normal; back along the ray to the boundary's plane
        // is offset / |cos| (bounded, for grazing rays, by 10 offsets).
        self.gap = (origin - hit.p).length() / hit.ng.dot(dir).abs().max(0.1);
        self.ray = Ray::new(origin, dir);
        true
    }

    /// What the ray met at `hit`, the end of the last segment: a surface that scatters (its
    /// BSDF), or a null boundary (or a hidden emitter), which is crossed ([`RayWalk::cross`]).
    #[inline]
    pub fn reach(&mut self, scene: &Scene, hit: &Hit) -> Reached {
        let hidden = self.skip_emitters && scene.object(hit).light.is_some();
        if !hidden && let Some(bsdf) = scene.bsdf(hit) {
            Reached::Surface(bsdf)
        } else if self.cross(scene, hit) {
            Reached::Crossed
        } else {
            Reached::Ended
        }
    }

    /// Goes on from a surface at `hit` in direction `wi` (reflected or refracted): refraction
    /// into or out of a volume changes the medium, reflection keeps it.
    #[inline]
    pub fn scatter_at_surface(&mut self, scene: &Scene, hit: &Hit, wi: Vec3) {
        self.medium = scene.medium_after(hit, wi, self.medium);
        self.ray = Ray::new(offset_origin(hit.p, hit.ng, wi), wi);
        self.gap = 0.0;
        self.crossings = 0;
        self.skip_emitters = false;
    }

    /// Goes on from a scattering event at `x` in a medium, in direction `wi`.
    #[inline]
    pub fn scatter_in_medium(&mut self, x: Vec3, wi: Vec3) {
        self.ray = Ray::new(x, wi);
        self.gap = 0.0;
        self.crossings = 0;
        self.skip_emitters = false;
    }
}

/// The first surface a ray starting in `medium` meets that is not a null boundary (whatever
/// its material), and the segment that reached it; None if the ray leaves the scene or passes
/// the crossing limit.
pub fn first_surface(
    scene: &Scene,
    ray: Ray,
    medium: Option<u32>,
    rays: &mut u64,
) -> Option<(Hit, Segment)> {
    let mut walk = RayWalk::new(ray, medium);
    loop {
        let seg = walk.segment(scene, rays);
        let hit = seg.hit?;
        match walk.reach(scene, &hit) {
            Reached::Surface(_) => return Some((hit, seg)),
            Reached::Crossed => continue,
            Reached::Ended => return None,
        }
    }
}

/// The first point of a camera path where radiance is estimated (the first non-delta, non-
/// glossy one: see [`walk_to_diffuse`]).
#[derive(Clone, Copy, Debug)]
pub struct VisiblePoint {
    pub hit: Hit,
    pub bsdf: Bsdf,
    /// Direction towards the camera (along the path).
    pub wo: Vec3,
    /// Surface normal on the side `wo` is on.
    pub n: Vec3,
    /// Throughput of the bounces and media before it.
    pub beta: Rgb,
    /// Bounces (delta or glossy) before it: photons gathered here may have at most max_depth - bounces
    /// scattering events.
    pub bounces: u32,
    /// Length of the path from the camera (for the pixel's footprint).
    pub distance: f32,
    /// The medium the path arrived in (None: vacuum).
    pub medium: Option<u32>,
}

/// A camera path followed through null boundaries, media and delta surfaces.
#[derive(Clone, Copy, Debug)]
pub struct CameraPath {
    /// Radiance met along the way, weighted by the throughput: emission (the visible point's
    /// own included, E S* L paths) and what the media scattered towards the camera.
    pub emitted: Rgb,
    /// `emitted`'s terms from the media alone (what they scattered towards the camera), and
    /// the rest (emission, and the direct light of the glossy vertices followed), each summed
    /// apart for `foton render --techniques`: `emitted` is their sum to float rounding.
    pub in_scattered: Rgb,
    pub emission: Rgb,
    /// None if the path left the scene, ended on a delta surface or at `max_depth` bounces.
    pub visible: Option<VisiblePoint>,
}

/// What a camera walk does on a segment through a medium that interacts: returns the radiance
/// the medium scatters towards the camera along it (unweighted by the throughput before it).
/// Its arguments: the segment, its medium, the delta bounces before it, the sampler and the
/// ray counter.
pub trait InMedium: FnMut(&Segment, &dyn Medium, u32, &mut Sampler, &mut u64) -> Rgb {}
impl<F: FnMut(&Segment, &dyn Medium, u32, &mut Sampler, &mut u64) -> Rgb> InMedium for F {}

/// How a camera walk treats the surfaces it meets.
#[derive(Clone, Copy, Debug)]
pub struct CameraWalk {
    /// Bounces the walk may take (the scene's `max_depth`).
    pub max_depth: u32,
    /// Lobes with a roughness (microfacet alpha) below this are continued through by sampling
    /// instead of being estimated from photons (0: only delta lobes are).
    pub glossy_roughness: f32,
}

impl CameraWalk {
    /// The photon integrators' shared parameter `glossy_roughness` (default
    /// [`GLOSSY_ROUGHNESS`]), with the scene's `max_depth`.
    pub fn read(props: &Properties<'_>, scene: &Scene) -> Result<CameraWalk> {
        let glossy_roughness = props.f32("glossy_roughness", GLOSSY_ROUGHNESS)?;
        if glossy_roughness < 0.0 || glossy_roughness.is_nan() {
            return Err(props.error(
                "glossy_roughness",
                format!("must be zero or positive, found {glossy_roughness}"),
            ));
        }
        Ok(CameraWalk {
            max_depth: scene.render.max_depth,
            glossy_roughness,
        })
    }
}

/// Default `glossy_roughness`: microfacet lobes with alpha below one half (most glossy
/// materials) are sampled; rougher ones, nearly diffuse, are estimated from photons.
pub const GLOSSY_ROUGHNESS: f32 = 0.5;

/// Follows a camera ray through null boundaries, delta and glossy bounces (at most
/// `max_depth`) to its first point whose radiance is estimated from photons: a surface whose
/// BSDF is neither delta nor glossy. This is the photon integrators' method for glossy
/// surfaces seen from the camera (Mitsuba 0.6's photon mapper's): a lobe rougher than
/// `glossy_roughness` is estimated from the photons there; a smoother one, whose reflection
/// a density estimate would blur, is continued through by sampling it, with next-event
/// estimation at the glossy vertex and the emission the sampled ray meets weighted against it
/// (the power heuristic). Lobes that transmit (rough glass) are always continued through: a
/// surface estimate sees the photons of one side only. A BSDF that mixes a delta part with a non-delta one (a smooth
/// plastic) picks one by its sampling probabilities: the delta part is continued through, the
/// other estimated here, each weighted by one over its probability.
///
/// On each segment through a medium, `in_medium` gives the in-scattered radiance and the
/// throughput is then multiplied by the segment's transmittance (so that surfaces behind it
/// are seen through it).
pub fn walk_to_diffuse(
    scene: &Scene,
    ray: Ray,
    how: CameraWalk,
    sampler: &mut Sampler,
    rays: &mut u64,
    mut in_medium: impl InMedium,
) -> CameraPath {
    let mut walk = RayWalk::camera(scene, ray);
    let mut emitted = Rgb::ZERO;
    let (mut in_scattered, mut emission) = (Rgb::ZERO, Rgb::ZERO);
    let mut beta = Rgb::ONE;
    let mut bounces = 0u32;
    let mut distance = 0.0;
    // The last bounce's solid-angle pdf and point, if it was glossy (MIS for the emission its
    // ray meets); None after the camera or a delta bounce.
    let mut glossy_from: Option<(f32, Vec3)> = None;
    let hidden = scene.render.hide_emitters;
    loop {
        let seg = walk.segment(scene, rays);
        if let Some(m) = seg.interacting_medium(scene) {
            if m.is_emissive() {
                // The medium's own emission along the segment, by one free-flight sample
                // (the collision estimator, as `path` finds it).
                let c = crate::medium::channel(sampler.next_f32());
                let flight =
                    m.sample_free_flight(&seg.start(), seg.length(), c, sampler.next_f32());
                let e = beta * flight.emission_weight();
                emitted += e;
                emission += e;
            }
            let scattered = beta * in_medium(&seg, m, bounces, sampler, rays);
            emitted += scattered;
            in_scattered += scattered;
            beta *= m.transmittance(&seg.start(), seg.length());
            if beta == Rgb::ZERO {
                break;
            }
        }
        let Some(hit) = seg.hit else {
            if let Some((light_id, le)) = scene.escaped(seg.ray.dir)
                && !(hidden && bounces == 0)
            {
                let far = glossy_from.map(|(_, p)| p + seg.ray.dir);
                let w = emission_weight(scene, glossy_from, light_id, far, Vec3::ZERO);
                let e = beta * le * w;
                emitted += e;
                emission += e;
            }
            break;
        };
        distance += hit.p.distance(seg.ray.origin);
        let bsdf = match walk.reach(scene, &hit) {
            Reached::Surface(bsdf) => bsdf,
            Reached::Crossed => continue,
            Reached::Ended => break,
        };
        let wo = -seg.ray.dir;
        if let Some((light_id, _, le)) = seg.emitted(scene) {
            let w = emission_weight(scene, glossy_from, light_id, Some(hit.p), hit.ng);
            let e = beta * le * w;
            emitted += e;
            emission += e;
        }
        if bounces >= how.max_depth {
            break;
        }
        let glossy =
            bsdf.is_delta() || bsdf.lobe.transmits() || bsdf.roughness() < how.glossy_roughness;
        if glossy && !bsdf.is_delta() {
            let at = Scatter::Surface {
                hit: &hit,
                bsdf: &bsdf,
            };
            let mis = Mis::WithScatterSampling;
            let e = beta * estimate_direct(scene, at, wo, walk.medium, mis, sampler, rays);
            emitted += e;
            emission += e;
        }
        let p_delta = if glossy {
            0.0
        } else {
            bsdf.delta_probability(wo)
        };
        if glossy || p_delta > 0.0 {
            let (u, uc) = (sampler.next_2d(), sampler.next_f32());
            // `sample` picks the delta part exactly when uc < p_delta; the non-delta part
            // is estimated here whether or not its sampled direction would carry anything.
            if glossy || uc < p_delta {
                let Some(bs) = bsdf.sample(wo, u, uc, TransportMode::Radiance) else {
                    break;
                };
                beta *= bs.weight;
                bounces += 1;
                glossy_from = (!bs.delta).then_some((bs.pdf, hit.p));
                walk.scatter_at_surface(scene, &hit, bs.wi);
                continue;
            }
            // The non-delta part was picked: estimated here, for both parts' share.
            beta /= 1.0 - p_delta;
        }
        let n = if hit.ng.dot(wo) > 0.0 {
            hit.ng
        } else {
            -hit.ng
        };
        return CameraPath {
            emitted,
            in_scattered,
            emission,
            visible: Some(VisiblePoint {
                hit,
                bsdf,
                wo,
                n,
                beta,
                bounces,
                distance,
                medium: walk.medium,
            }),
        };
    }
    CameraPath {
        emitted,
        in_scattered,
        emission,
        visible: None,
    }
}

/// The MIS weight of emission met by the camera walk at `point` (normal `n`) on light
/// `light_id`: 1 after the camera or a delta bounce; after a glossy bounce `from` (its pdf and
/// point), the power heuristic against the light sample next-event estimation took there.
/// For a light at infinity `point` is any point along the direction (`n` unused).
fn emission_weight(
    scene: &Scene,
    from: Option<(f32, Vec3)>,
    light_id: u32,
    point: Option<Vec3>,
    n: Vec3,
) -> f32 {
    let (Some((pdf, x)), Some(point)) = (from, point) else {
        return 1.0;
    };
    let light = &scene.lights[light_id as usize];
    let pdf_light = scene.light_pmf(light_id as usize) * light.pdf_li(x, point, n);
    power_heuristic(pdf, pdf_light)
}

/// [`walk_to_diffuse`] for integrators that do not render media (the media are still
/// crossed: their transmittance applies, nothing is scattered from them).
pub fn trace_to_diffuse(
    scene: &Scene,
    ray: Ray,
    how: CameraWalk,
    sampler: &mut Sampler,
    rays: &mut u64,
) -> CameraPath {
    walk_to_diffuse(scene, ray, how, sampler, rays, |_, _, _, _, _| Rgb::ZERO)
}
