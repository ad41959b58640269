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
use crate::geometry::{Hit, Ray, offset_origin};
use crate::material::{Material, TransportMode};
use crate::medium::Medium;
use crate::sampling::Sampler;
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
}

/// What a walk's ray met at the end of a segment ([`RayWalk::reach`]).
#[derive(Clone, Copy, Debug)]
pub enum Reached {
    /// A surface that scatters, with its material.
    Surface(Material),
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
    /// material), or a null boundary, which is crossed ([`RayWalk::cross`]).
    #[inline]
    pub fn reach(&mut self, scene: &Scene, hit: &Hit) -> Reached {
        let material = *scene.material(hit);
        if !material.is_null() {
            Reached::Surface(material)
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
    }

    /// Goes on from a scattering event at `x` in a medium, in direction `wi`.
    #[inline]
    pub fn scatter_in_medium(&mut self, x: Vec3, wi: Vec3) {
        self.ray = Ray::new(x, wi);
        self.gap = 0.0;
        self.crossings = 0;
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

/// The first non-delta point of a camera path.
#[derive(Clone, Copy, Debug)]
pub struct VisiblePoint {
    pub hit: Hit,
    pub material: Material,
    /// Direction towards the camera (along the path).
    pub wo: Vec3,
    /// Surface normal on the side `wo` is on.
    pub n: Vec3,
    /// Throughput of the delta bounces and media before it.
    pub beta: Rgb,
    /// Delta bounces before it: photons gathered here may have at most max_depth - bounces
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
    /// None if the path left the scene, ended on a delta surface or at `max_depth` bounces.
    pub visible: Option<VisiblePoint>,
}

/// What a camera walk does on a segment through a medium that interacts: returns the radiance
/// the medium scatters towards the camera along it (unweighted by the throughput before it).
/// Its arguments: the segment, its medium, the delta bounces before it, the sampler and the
/// ray counter.
pub trait InMedium: FnMut(&Segment, &dyn Medium, u32, &mut Sampler, &mut u64) -> Rgb {}
impl<F: FnMut(&Segment, &dyn Medium, u32, &mut Sampler, &mut u64) -> Rgb> InMedium for F {}

/// Follows a camera ray through null boundaries and at most `max_depth` delta bounces
/// (sampling reflection or refraction in radiance mode) to its first non-delta surface. On
/// each segment through a medium, `in_medium` gives the in-scattered radiance and the
/// throughput is then multiplied by the segment's transmittance (so that surfaces behind it
/// are seen through it).
pub fn walk_to_diffuse(
    scene: &Scene,
    ray: Ray,
    max_depth: u32,
    sampler: &mut Sampler,
    rays: &mut u64,
    mut in_medium: impl InMedium,
) -> CameraPath {
    let mut walk = RayWalk::new(ray, scene.camera_medium);
    let mut emitted = Rgb::ZERO;
    let mut beta = Rgb::ONE;
    let mut bounces = 0u32;
    let mut distance = 0.0;
    loop {
        let seg = walk.segment(scene, rays);
        if let Some(m) = seg.interacting_medium(scene) {
            emitted += beta * in_medium(&seg, m, bounces, sampler, rays);
            beta *= m.transmittance(&seg.start(), seg.length());
            if beta == Rgb::ZERO {
                break;
            }
        }
        let Some(hit) = seg.hit else {
            if let Some((_, le)) = scene.escaped(seg.ray.dir) {
                emitted += beta * le;
            }
            break;
        };
        distance += hit.p.distance(seg.ray.origin);
        let material = match walk.reach(scene, &hit) {
            Reached::Surface(material) => material,
            Reached::Crossed => continue,
            Reached::Ended => break,
        };
        let wo = -seg.ray.dir;
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
            walk.scatter_at_surface(scene, &hit, bs.wi);
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
                medium: walk.medium,
            }),
        };
    }
    CameraPath {
        emitted,
        visible: None,
    }
}

/// [`walk_to_diffuse`] for integrators that do not render media (the media are still
/// crossed: their transmittance applies, nothing is scattered from them).
pub fn trace_to_diffuse(
    scene: &Scene,
    ray: Ray,
    max_depth: u32,
    sampler: &mut Sampler,
    rays: &mut u64,
) -> CameraPath {
    walk_to_diffuse(scene, ray, max_depth, sampler, rays, |_, _, _, _, _| {
        Rgb::ZERO
    })
}
