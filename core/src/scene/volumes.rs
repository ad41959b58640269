//! Where media are: the medium interfaces of shapes, written in the file (Mitsuba's interior
//! and exterior) or found from how closed shapes nest; the medium at a point, and the medium a
//! ray enters or leaves into at a boundary.

use super::{Named, Object, Scene};
use crate::accel::Accel;
use crate::geometry::{Hit, Ray, Shape};
use crate::material::Material;
use glam::{Vec2, Vec3};

/// The media on the two sides of a shape: pbrt's MediumInterface, Mitsuba's interior and
/// exterior. A ray crossing the shape against its normal enters `inside`, along it leaves to
/// `outside`, so that every boundary crossing sets the medium afresh and an error made
/// between two crossings does not propagate along the path. Either both sides are written in
/// the file (`exterior` given: any shape, open or closed), or the shape is closed and bounds
/// a volume whose outside is found from how the volumes nest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MediumInterface {
    /// The `interior` medium; None: vacuum (clear glass, a bubble).
    pub inside: Option<u32>,
    /// The `exterior` medium, or the inside of the innermost volume enclosing this one, or
    /// the scene medium.
    pub outside: Option<u32>,
    /// Number of volumes enclosing this one (0: outermost, or an open shape). Decides between
    /// coincident boundaries.
    pub depth: u32,
}

impl Scene {
    /// The medium at a point in free space: the inside of the innermost medium boundary that
    /// contains it, or the scene medium. An error (saying why) if the point lies on a boundary
    /// or inside boundaries that overlap without one containing the other. Costs a few rays
    /// per boundary: for starting points (camera, lights), not for every vertex of a path.
    pub fn medium_at(&self, p: Vec3) -> std::result::Result<Option<u32>, String> {
        locate_medium(
            &self.accel,
            &self.objects,
            &self.interfaces,
            &self.volumes,
            self.medium,
            p,
        )
    }

    /// A box around the region medium `id` fills: the shapes on either side of which it is.
    /// None if it is the scene's medium (it fills all space outside the shapes) or no shape
    /// borders it. For sampling points of an emitting medium: within its region the medium at
    /// a point is still [`Scene::medium_at`]'s.
    pub fn medium_region(&self, id: u32) -> Option<(Vec3, Vec3)> {
        if self.medium == Some(id) {
            return None;
        }
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for prim in self.accel.primitives() {
            let Some(Some(iface)) = self.interfaces.get(prim.object as usize) else {
                continue;
            };
            if iface.inside == Some(id) || iface.outside == Some(id) {
                let b = prim.shape.aabb();
                lo = lo.min(Vec3::from(b.min));
                hi = hi.max(Vec3::from(b.max));
            }
        }
        lo.cmple(hi).all().then_some((lo, hi))
    }

    /// The medium light `i` emits into (None: vacuum): the one the file puts it in (a point or
    /// spot light's `medium`, an area light's exterior when its shape names it), or the one
    /// found just off its emitting side (an area light is taken to lie in one medium). An
    /// error (saying why) where [`Scene::medium_at`] gives one.
    pub fn light_medium(&self, i: usize) -> std::result::Result<Option<u32>, String> {
        if !self.has_media() {
            return Ok(None);
        }
        if let Some(given) = self.light_media[i] {
            return Ok(given);
        }
        let scale = 1.0 + (self.bounds.1 - self.bounds.0).length();
        let e = self.lights[i].sample_emission(Vec2::splat(0.5), Vec2::splat(0.5), 0.5);
        self.medium_at(e.origin + e.n * (1e-3 * scale))
    }

    /// The medium each light emits into ([`Scene::light_medium`] for every light), found once
    /// per render (a few rays per medium boundary) by whatever starts paths at the lights.
    pub fn emission_media(&self) -> crate::error::Result<Vec<Option<u32>>> {
        (0..self.lights.len())
            .map(|i| {
                self.light_medium(i).map_err(|why| {
                    crate::error::Error::Render(format!(
                        "{}: cannot tell which medium light {i} is in: {why}",
                        self.file.display()
                    ))
                })
            })
            .collect()
    }

    /// The medium on the side of the surface at `hit` that `dir` points into: the medium a
    /// ray crossing the surface along `dir` enters, or the one a ray leaving the surface
    /// along `dir` (reflected, or a shadow ray) travels in. `current` is the medium the path
    /// was in; it is kept unless the surface is a medium interface (Mitsuba's medium
    /// transition).
    ///
    /// A shape whose file names both its media is taken as written (Mitsuba's
    /// `target_medium`). Coincident boundaries of volumes found from their nesting (two
    /// volumes touching, a volume sharing a face with its container) are crossed together:
    /// every such boundary through the point is found, and the innermost one entered wins, or
    /// if none is entered, the outermost one left.
    #[inline]
    pub fn medium_after(&self, hit: &Hit, dir: Vec3, current: Option<u32>) -> Option<u32> {
        // Without media no surface is an interface: no call per bounce (about 1.5% of the path
        // tracer's instructions on the Cornell box).
        if !self.has_media {
            return current;
        }
        self.medium_across(hit, dir, current)
    }

    /// [`Scene::medium_after`] in a scene with media.
    fn medium_across(&self, hit: &Hit, dir: Vec3, current: Option<u32>) -> Option<u32> {
        let object = self.primitive(hit).object as usize;
        let Some(own) = self.interfaces[object] else {
            return current;
        };
        if self.alone[object] {
            return if hit.ng.dot(dir) < 0.0 {
                own.inside
            } else {
                own.outside
            };
        }
        let eps = 1e-4 * (1.0 + hit.p.abs().max_element());
        let probe = Ray::new(hit.p - dir * eps, dir);
        let mut entered: Option<MediumInterface> = None;
        let mut left: Option<MediumInterface> = None;
        let mut consider = |iface: MediumInterface, n: Vec3| {
            if n.dot(dir) < 0.0 {
                if entered.is_none_or(|e| iface.depth > e.depth) {
                    entered = Some(iface);
                }
            } else if left.is_none_or(|l| iface.depth < l.depth) {
                left = Some(iface);
            }
        };
        consider(own, hit.ng);
        let prims = self.accel.primitives();
        self.accel.for_each_hit(&probe, 2.0 * eps, |i, t| {
            let prim = &prims[i as usize];
            if self.objects[prim.object as usize].explicit_media {
                return;
            }
            if let Some(iface) = self.interfaces[prim.object as usize] {
                consider(iface, prim.shape.normal(probe.at(t)));
            }
        });
        match (entered, left) {
            (Some(e), _) => e.inside,
            (None, Some(l)) => l.outside,
            (None, None) => current,
        }
    }
}

/// An object that bounds a volume, with what point-in-volume tests need.
pub(super) struct Volume {
    object: u32,
    /// Its primitives (indices into the BVH's primitives).
    prims: Vec<u32>,
    /// Its bounding box.
    lo: Vec3,
    hi: Vec3,
}

/// Directions of the rays that decide whether a point is inside a closed shape: five, not
/// aligned with the axes (axis-aligned rays run along the edges and faces of boxes).
const INSIDE_PROBES: [Vec3; 5] = [
    Vec3::new(0.267_261_24, 0.534_522_5, 0.801_783_7),
    Vec3::new(-0.617_213_4, 0.154_303_35, 0.771_516_8),
    Vec3::new(0.408_248_3, -0.816_496_6, 0.408_248_3),
    Vec3::new(-0.301_511_35, -0.301_511_35, -0.904_534_04),
    Vec3::new(0.872_871_6, 0.218_217_9, -0.436_435_8),
];

/// Whether `p` is inside a volume: along each probe direction, the nearest surface of the
/// volume is seen from its inside (outward normal along the ray) or not; the majority decides,
/// so that a probe that slips through an edge between two triangles does not. Err if `p` is
/// on the surface.
fn inside_volume(accel: &Accel, volume: &Volume, p: Vec3) -> std::result::Result<bool, ()> {
    let on_surface = 1e-5 * (1.0 + p.abs().max_element());
    if (p - volume.lo).min_element() < -on_surface || (volume.hi - p).min_element() < -on_surface {
        return Ok(false);
    }
    let prims = accel.primitives();
    // The probes cannot see a surface at distance zero: a point on it is found by distance.
    if volume
        .prims
        .iter()
        .any(|&i| distance_to(&prims[i as usize].shape, p) < on_surface)
    {
        return Err(());
    }
    let mut votes = 0;
    for dir in INSIDE_PROBES {
        let ray = Ray::new(p, dir);
        let mut nearest: Option<(f32, u32)> = None;
        accel.for_each_hit(&ray, f32::INFINITY, |i, t| {
            if prims[i as usize].object == volume.object && nearest.is_none_or(|(tn, _)| t < tn) {
                nearest = Some((t, i));
            }
        });
        if let Some((t, i)) = nearest {
            if t < on_surface {
                return Err(());
            }
            let n = prims[i as usize].shape.normal(ray.at(t));
            votes += (n.dot(dir) > 0.0) as u32;
        }
    }
    Ok(votes * 2 > INSIDE_PROBES.len() as u32)
}

/// Distance from `p` to a closed object's primitive (spheres and triangles; quads are never
/// closed).
fn distance_to(shape: &Shape, p: Vec3) -> f32 {
    let segment = |a: Vec3, e: Vec3| {
        let s = ((p - a).dot(e) / e.length_squared()).clamp(0.0, 1.0);
        p.distance(a + s * e)
    };
    match *shape {
        Shape::Sphere { center, radius, .. } => (p.distance(center) - radius).abs(),
        Shape::Triangle { p0, e1, e2 } => {
            // The nearest point is inside the triangle (the projection) or on an edge.
            let n = e1.cross(e2);
            let q = p - p0;
            let b1 = q.cross(e2).dot(n) / n.length_squared();
            let b2 = e1.cross(q).dot(n) / n.length_squared();
            if b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 {
                q.dot(n).abs() / n.length()
            } else {
                segment(p0, e1)
                    .min(segment(p0, e2))
                    .min(segment(p0 + e1, e2 - e1))
            }
        }
        Shape::Quad { origin, u, v, .. } => segment(origin, u)
            .min(segment(origin, v))
            .min(segment(origin + u, v))
            .min(segment(origin + v, u)),
        // Never closed either; the distance to its plane is a lower bound.
        Shape::Disk { center, normal, .. } => (p - center).dot(normal).abs(),
        // Never closed: the distance to the sphere of the nearest point on the axis, which
        // is within the piece's taper of the distance to its surface.
        Shape::Curve { p0, r0, p1, r1, .. } => {
            let e = p1 - p0;
            let s = ((p - p0).dot(e) / e.length_squared().max(f32::MIN_POSITIVE)).clamp(0.0, 1.0);
            (p.distance(p0 + s * e) - (r0 + s * (r1 - r0))).abs()
        }
    }
}

/// A point strictly inside a closed object, near its surface: the centroid of its largest
/// primitive pushed inwards (the centre, for a sphere). Used to ask which boundaries contain
/// the object.
fn point_inside(accel: &Accel, volume: &Volume) -> Vec3 {
    let mut best: Option<(f32, Shape)> = None;
    for &i in &volume.prims {
        let prim = &accel.primitives()[i as usize];
        let area = prim.shape.area();
        if best.is_none_or(|(a, _)| area > a) {
            best = Some((area, prim.shape));
        }
    }
    match best.map(|(_, s)| s) {
        Some(Shape::Sphere { center, .. }) => center,
        Some(Shape::Triangle { p0, e1, e2 }) => {
            let c = p0 + (e1 + e2) / 3.0;
            let inward = -e1.cross(e2).normalize();
            // Far enough from the surface for the probes' on-surface test, well inside any
            // triangle-sized feature.
            let step =
                (1e-3 * (1.0 + c.abs().max_element())).min(0.05 * e1.length().min(e2.length()));
            c + inward * step
        }
        Some(Shape::Quad {
            origin,
            u,
            v,
            normal,
            ..
        }) => origin + 0.5 * (u + v) - normal * 1e-3,
        Some(Shape::Disk { center, normal, .. }) => center - normal * 1e-3,
        Some(Shape::Curve { p0, .. }) => p0,
        None => Vec3::ZERO,
    }
}

/// Warnings for medium boundaries (null shapes that bound a medium) lying on an opaque
/// surface: a boundary face and a floor in the same plane, which rays restarted past the
/// boundary can slip through (docs/scene-format.md, "where the media are"). Each boundary
/// triangle, quad and disk is probed at its centroid and near its corners by a ray across
/// its plane; one warning per pair of objects.
pub(super) fn coincident_boundaries(
    objects: &[Object],
    materials: &[Named<Material>],
    interfaces: &[Option<MediumInterface>],
    accel: &Accel,
) -> Vec<String> {
    let null = |o: u32| {
        materials[objects[o as usize].material as usize]
            .value
            .is_null()
    };
    let mut pairs: Vec<(u32, u32, Vec3)> = Vec::new();
    for prim in accel.primitives() {
        let o = prim.object;
        let bounds_medium =
            interfaces[o as usize].is_some_and(|i| i.inside.is_some() || i.outside.is_some());
        if !bounds_medium || !null(o) {
            continue;
        }
        let (centre, corners) = match prim.shape {
            Shape::Triangle { p0, e1, e2 } => (p0 + (e1 + e2) / 3.0, [p0, p0 + e1, p0 + e2]),
            Shape::Quad { origin, u, v, .. } => {
                (origin + 0.5 * (u + v), [origin, origin + u + v, origin + u])
            }
            Shape::Disk { center, u, v, .. } => (center, [center + u, center + v, center - u]),
            Shape::Sphere { .. } | Shape::Curve { .. } => continue,
        };
        let n = prim.shape.normal(centre);
        let size = corners
            .iter()
            .map(|c| c.distance(centre))
            .fold(0.0, f32::max);
        let delta = 1e-4 * centre.abs().max_element().max(size);
        for p in std::iter::once(centre).chain(corners.map(|c| centre + 0.9 * (c - centre))) {
            let ray = Ray::new(p + n * delta, -n);
            accel.for_each_hit(&ray, 2.0 * delta, |k, _| {
                let other = &accel.primitives()[k as usize];
                let q = other.object;
                if q != o
                    && !null(q)
                    && other.shape.is_flat()
                    && other.shape.normal(p).dot(n).abs() > 0.99
                    && !pairs.iter().any(|&(a, b, _)| a == o && b == q)
                {
                    pairs.push((o, q, p));
                }
            });
        }
    }
    pairs
        .into_iter()
        .map(|(o, q, p)| {
            format!(
                "{}, a medium boundary, lies on the surface of {} (at {:.4}, {:.4}, {:.4}): rays \
                 restarted past the boundary can slip through that surface; move the boundary \
                 off it a little (a fog box 1 mm above the floor)",
                objects[o as usize].name, objects[q as usize].name, p.x, p.y, p.z
            )
        })
        .collect()
}

/// Which objects bound volumes, and the medium interfaces of all objects. A shape whose file
/// names its `exterior` has the interface written there; it bounds a volume if it is closed
/// (and not a sphere turned inside out). Another closed shape bounds a volume if it has an
/// `interior` medium, or if light can enter it (a null or dielectric material): then its
/// inside is vacuum (clear glass in fog), and its outside is the inside of the innermost
/// volume around it. Other shapes leave the medium as it is (light reflected there stays on
/// its side). Also returns, per object, whether it is an interface crossed without a search
/// for coincident boundaries (written in the file, or a volume no other one comes near).
pub(super) fn medium_interfaces(
    objects: &[Object],
    materials: &[Named<Material>],
    accel: &Accel,
    scene_medium: Option<u32>,
) -> (Vec<Option<MediumInterface>>, Vec<Volume>, Vec<bool>) {
    let mut index = vec![None; objects.len()];
    let mut volumes: Vec<Volume> = Vec::new();
    // A sphere turned inside out has its interior outside it: no volume to locate points in.
    let mut inside_out = vec![false; objects.len()];
    for p in accel.primitives() {
        if matches!(p.shape, Shape::Sphere { inward: true, .. }) {
            inside_out[p.object as usize] = true;
        }
    }
    for (i, o) in objects.iter().enumerate() {
        let m = &materials[o.material as usize].value;
        let bounds = if o.explicit_media {
            !inside_out[i]
        } else {
            o.interior.is_some() || m.is_null() || m.encloses_volume()
        };
        if o.closed && bounds {
            index[i] = Some(volumes.len());
            volumes.push(Volume {
                object: i as u32,
                prims: Vec::new(),
                lo: Vec3::splat(f32::INFINITY),
                hi: Vec3::splat(f32::NEG_INFINITY),
            });
        }
    }
    for (k, prim) in accel.primitives().iter().enumerate() {
        if let Some(v) = index[prim.object as usize] {
            let volume: &mut Volume = &mut volumes[v];
            volume.prims.push(k as u32);
            let b = prim.shape.aabb();
            volume.lo = volume.lo.min(b.min.into());
            volume.hi = volume.hi.max(b.max.into());
        }
    }
    // containers[k]: the volumes that contain volume k.
    let containers: Vec<Vec<usize>> = volumes
        .iter()
        .enumerate()
        .map(|(k, volume)| {
            let q = point_inside(accel, volume);
            (0..volumes.len())
                .filter(|&c| c != k && inside_volume(accel, &volumes[c], q).unwrap_or(false))
                .collect()
        })
        .collect();
    let depth: Vec<u32> = containers.iter().map(|c| c.len() as u32).collect();
    let mut out: Vec<Option<MediumInterface>> = objects
        .iter()
        .map(|o| {
            o.explicit_media.then_some(MediumInterface {
                inside: o.interior,
                outside: o.exterior,
                depth: 0,
            })
        })
        .collect();
    let mut alone: Vec<bool> = objects.iter().map(|o| o.explicit_media).collect();
    for (k, volume) in volumes.iter().enumerate() {
        let parent = containers[k].iter().copied().max_by_key(|&c| depth[c]);
        let i = volume.object as usize;
        let iface = out[i].get_or_insert(MediumInterface {
            inside: objects[i].interior,
            outside: parent.map_or(scene_medium, |c| {
                objects[volumes[c].object as usize].interior
            }),
            depth: 0,
        });
        iface.depth = depth[k];
    }
    let pad = |v: &Volume| 1e-3 * (1.0 + v.lo.abs().max(v.hi.abs()).max_element());
    let inferred = |v: &Volume| !objects[v.object as usize].explicit_media;
    for (k, v) in volumes.iter().enumerate().filter(|(_, v)| inferred(v)) {
        alone[v.object as usize] = volumes.iter().enumerate().all(|(c, w)| {
            let e = pad(v).max(pad(w));
            c == k || !inferred(w) || (v.lo - e).cmpgt(w.hi).any() || (w.lo - e).cmpgt(v.hi).any()
        });
    }
    (out, volumes, alone)
}

/// See [`Scene::medium_at`].
pub(super) fn locate_medium(
    accel: &Accel,
    objects: &[Object],
    interfaces: &[Option<MediumInterface>],
    volumes: &[Volume],
    scene_medium: Option<u32>,
    p: Vec3,
) -> std::result::Result<Option<u32>, String> {
    let mut innermost: Option<(usize, MediumInterface)> = None;
    for volume in volumes {
        let i = volume.object as usize;
        let Some(iface) = interfaces[i] else { continue };
        match inside_volume(accel, volume, p) {
            Err(()) => {
                return Err(format!(
                    "it lies on the surface of {}, a medium boundary",
                    objects[i].name
                ));
            }
            Ok(false) => {}
            Ok(true) => match innermost {
                Some((j, other)) if other.depth == iface.depth => {
                    return Err(format!(
                        "it is inside both {} and {}, which overlap without one containing the other",
                        objects[j].name, objects[i].name
                    ));
                }
                Some((_, other)) if other.depth > iface.depth => {}
                _ => innermost = Some((i, iface)),
            },
        }
    }
    Ok(innermost.map_or(scene_medium, |(_, iface)| iface.inside))
}
