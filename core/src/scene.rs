//! Scene loading: one TOML file (see docs/scene-format.md) into the structures integrators use.
//!
//! Every table is read through a [`Properties`] bag, so every error names file, line, key path
//! and what was expected, and every key that was never read is reported as unused.

use crate::Rgb;
use crate::accel::Accel;
use crate::camera::Camera;
use crate::error::{Location, Result};
use crate::geometry::{Hit, Primitive, Ray, Shape, offset_origin};
use crate::light::{Light, area_light};
use crate::material::Material;
use crate::medium::{Homogeneous, Phase};
use crate::props::Properties;
use crate::sampling::Distribution1D;
use crate::value::{Document, Value};
use glam::{Mat4, Vec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug)]
pub struct RenderSettings {
    /// Name of the integrator plugin.
    pub integrator: String,
    /// Camera samples per pixel.
    pub spp: u32,
    pub seed: u64,
    /// Scattering events, pbrt style: 0 = emitters seen directly, 1 = direct lighting.
    pub max_depth: u32,
}

#[derive(Clone, Debug)]
pub struct FilmSettings {
    pub width: u32,
    pub height: u32,
    /// Resolved against the scene file's folder.
    pub output: PathBuf,
}

/// What a primitive belongs to: a `[[shapes]]` entry.
#[derive(Clone, Debug)]
pub struct Object {
    /// "shapes[3]" (its key path) for messages.
    pub name: String,
    pub material: u32,
    /// The area light this object is, if it emits.
    pub light: Option<u32>,
    /// Medium inside the (closed) shape.
    pub interior: Option<u32>,
    /// Whether the shape is closed (a sphere, a watertight consistently oriented mesh).
    pub closed: bool,
}

/// The media on the two sides of a closed shape that bounds a volume: pbrt's MediumInterface,
/// except that the outside is not written in the scene but found from how the shapes nest.
/// A ray crossing the shape against its outward normal enters `inside`, along it leaves to
/// `outside`, so that every boundary crossing sets the medium afresh and an error made
/// between two crossings does not propagate along the path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MediumInterface {
    /// The `interior` medium; None: vacuum (clear glass, a bubble).
    pub inside: Option<u32>,
    /// The inside of the innermost boundary enclosing this one, or the scene medium.
    pub outside: Option<u32>,
    /// Number of boundaries enclosing this one (0: outermost). Decides between coincident
    /// boundaries.
    pub depth: u32,
}

/// A named material or medium, as referenced from shapes.
#[derive(Clone, Debug)]
pub struct Named<T> {
    pub name: String,
    pub value: T,
}

pub struct Scene {
    pub file: PathBuf,
    pub render: RenderSettings,
    pub film: FilmSettings,
    pub camera: Camera,
    pub materials: Vec<Named<Material>>,
    pub media: Vec<Named<Homogeneous>>,
    pub objects: Vec<Object>,
    pub lights: Vec<Light>,
    /// Chooses a light proportionally to its power.
    pub light_distribution: Distribution1D,
    pub accel: Accel,
    /// The medium filling free space, if any.
    pub medium: Option<u32>,
    /// Per object: its medium interface if it bounds a volume (see [`MediumInterface`]); all
    /// None in a scene without media.
    pub interfaces: Vec<Option<MediumInterface>>,
    /// The medium around the camera (None: vacuum).
    pub camera_medium: Option<u32>,
    /// The objects that bound volumes, for [`Scene::medium_at`].
    volumes: Vec<Volume>,
    /// Per object: a volume whose bounding box meets no other volume's, so that no other
    /// boundary can coincide with it and crossing it needs no search for coincident ones.
    alone: Vec<bool>,
    /// Axis-aligned bounds of all geometry and point lights.
    pub bounds: (Vec3, Vec3),
    /// The parsed document (integrators read their `[integrators.NAME]` table from it).
    pub document: Document,
    /// Keys that were present but never read by the loader (not counting `[integrators]`).
    pub unused: Vec<(String, Location)>,
    /// Non-fatal problems (reflectance above one, no lights...).
    pub warnings: Vec<String>,
}

const SECTIONS: &[&str] = &[
    "render",
    "film",
    "camera",
    "integrators",
    "materials",
    "media",
    "shapes",
    "lights",
    "scene",
];
const MATERIAL_TYPES: &[&str] = &["diffuse", "mirror", "dielectric", "null"];
const SHAPE_TYPES: &[&str] = &["sphere", "quad", "mesh"];
const LIGHT_TYPES: &[&str] = &["point"];
const MEDIUM_TYPES: &[&str] = &["homogeneous"];

/// Collects the bags of a load so that unused keys can be listed at the end.
struct Loader {
    dir: PathBuf,
    bags: Vec<Vec<(String, Location)>>,
    warnings: Vec<String>,
}

impl Loader {
    fn done(&mut self, bag: &Properties<'_>) {
        self.bags.push(bag.unused());
    }

    fn warn(&mut self, bag: &Properties<'_>, key: &str, message: String) {
        self.warnings.push(format!(
            "{}: `{}`: {message}",
            bag.location(key),
            bag.key_path(key)
        ));
    }
}

impl Scene {
    /// Loads a scene file, applying `--set` style overrides first.
    pub fn load(path: &Path, overrides: &[String]) -> Result<Scene> {
        let mut doc = Document::load(path)?;
        for o in overrides {
            doc.set(o)?;
        }
        Scene::from_document(doc)
    }

    pub fn from_document(doc: Document) -> Result<Scene> {
        let file = doc.file.clone();
        let dir = file.parent().map(Path::to_path_buf).unwrap_or_default();
        let mut ld = Loader {
            dir,
            bags: Vec::new(),
            warnings: Vec::new(),
        };
        let root = Properties::root(&file, &doc.root);
        for key in root.keys() {
            if !SECTIONS.contains(&key) {
                return Err(root.error(
                    key,
                    format!("unknown section; expected one of: {}", SECTIONS.join(", ")),
                ));
            }
        }
        root.node("integrators");

        let render = read_render(&root, &mut ld)?;
        let film = read_film(&root, &mut ld)?;
        let camera = read_camera(&root, &film, &mut ld)?;
        let (materials, material_index) = read_materials(&root, &mut ld)?;
        let (media, medium_index) = read_media(&root, &mut ld)?;

        let mut objects = Vec::new();
        let mut prims = Vec::new();
        let mut lights = Vec::new();
        read_shapes(
            &root,
            &mut ld,
            &materials,
            &material_index,
            &medium_index,
            &mut objects,
            &mut prims,
            &mut lights,
        )?;
        read_point_lights(&root, &mut ld, &mut lights)?;

        let mut medium = None;
        if let Some(scene) = root.table("scene")? {
            if let Some(name) = scene.string_opt("medium")? {
                medium = Some(*medium_index.get(name).ok_or_else(|| {
                    scene.error("medium", undefined("medium", name, &medium_index))
                })?);
            }
            ld.done(&scene);
        }

        if lights.is_empty() {
            ld.warnings.push(format!(
                "{}: the scene has no lights: the image will be black",
                file.display()
            ));
        }
        let powers: Vec<f32> = lights.iter().map(|l| crate::average(l.power())).collect();
        let light_distribution = Distribution1D::new(&powers);

        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for p in &prims {
            let b = p.shape.aabb();
            lo = lo.min(b.min.into());
            hi = hi.max(b.max.into());
        }
        for l in &lights {
            if let Light::Point { position, .. } = l {
                lo = lo.min(*position);
                hi = hi.max(*position);
            }
        }
        if !lo.is_finite() {
            lo = camera.position;
            hi = camera.position;
        }

        let accel = Accel::build(prims);
        let uses_media = medium.is_some() || objects.iter().any(|o| o.interior.is_some());
        let (interfaces, volumes, alone) = if uses_media {
            medium_interfaces(&objects, &materials, &accel, medium)
        } else {
            (
                vec![None; objects.len()],
                Vec::new(),
                vec![false; objects.len()],
            )
        };
        let mut camera_medium = None;
        if uses_media {
            camera_medium = locate_medium(
                &accel,
                &objects,
                &interfaces,
                &volumes,
                medium,
                camera.position,
            )
            .map_err(|why| {
                let t = root.table("camera").ok().flatten();
                let message =
                    format!("the medium around the camera is undefined: {why}; move the camera");
                match t {
                    Some(t) => t.error("position", message),
                    None => root.error("camera", message),
                }
            })?;
        }

        ld.done(&root);
        let mut unused: Vec<(String, Location)> = ld.bags.into_iter().flatten().collect();
        unused.sort_by(|a, b| (a.1.line, &a.0).cmp(&(b.1.line, &b.0)));
        let warnings = ld.warnings;
        Ok(Scene {
            file,
            render,
            film,
            camera,
            materials,
            media,
            objects,
            lights,
            light_distribution,
            accel,
            medium,
            interfaces,
            volumes,
            alone,
            camera_medium,
            bounds: (lo, hi),
            document: doc,
            unused,
            warnings,
        })
    }

    /// Where a key path was written in the scene file (line 0: it came from `--set`).
    pub fn location_of(&self, path: &[&str]) -> Option<Location> {
        let mut node = self.document.root.get(path.first()?)?;
        for key in &path[1..] {
            match &node.value {
                Value::Table(t) => node = t.get(key)?,
                _ => return None,
            }
        }
        Some(Location {
            file: self.file.clone(),
            line: node.line,
            column: node.column,
        })
    }

    /// The parameters of integrator `name` (its `[integrators.NAME]` table, or an empty bag).
    pub fn integrator_properties(&self, name: &str) -> Result<Properties<'_>> {
        let path = format!("integrators.{name}");
        let Some(node) = self.document.root.get("integrators") else {
            return Ok(Properties::empty(&self.file, &path));
        };
        let integrators = Properties::new(&self.file, "integrators", node)?;
        Ok(integrators
            .table(name)?
            .unwrap_or_else(|| Properties::empty(&self.file, &path)))
    }

    /// Closest surface hit (null boundaries included) with t in (0, tmax).
    #[inline]
    pub fn intersect(&self, ray: &Ray, tmax: f32) -> Option<Hit> {
        self.accel.intersect(ray, tmax)
    }

    #[inline]
    pub fn primitive(&self, hit: &Hit) -> &Primitive {
        &self.accel.primitives()[hit.prim as usize]
    }

    #[inline]
    pub fn object(&self, hit: &Hit) -> &Object {
        &self.objects[self.primitive(hit).object as usize]
    }

    #[inline]
    pub fn material(&self, hit: &Hit) -> &Material {
        &self.materials[self.object(hit).material as usize].value
    }

    /// The area light a hit lies on, if its object emits.
    #[inline]
    pub fn area_light(&self, hit: &Hit) -> Option<(u32, &Light)> {
        let id = self.object(hit).light?;
        Some((id, &self.lights[id as usize]))
    }

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

    /// The medium on the side of the surface at `hit` that `dir` points into: the medium a
    /// ray crossing the surface along `dir` enters, or the one a ray leaving the surface
    /// along `dir` (reflected, or a shadow ray) travels in. `current` is the medium the path
    /// was in; it is kept unless the surface bounds a volume.
    ///
    /// Coincident boundaries (two volumes touching, a volume sharing a face with its
    /// container) are crossed together: every boundary through the point is found, and the
    /// innermost one entered wins, or if none is entered, the outermost one left.
    pub fn medium_after(&self, hit: &Hit, dir: Vec3, current: Option<u32>) -> Option<u32> {
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

    /// Transmittance along the segment between two points, starting in `medium`: zero if
    /// anything but null boundaries blocks it, otherwise the product of exp(-sigma_t d) over
    /// the pieces between the null boundaries it crosses, each in its own medium. The ends
    /// are offset along their normals as in [`Scene::occluded`] (a zero normal, e.g. a point
    /// in a medium or a point light: no offset). Without media it is exactly 0 or 1.
    pub fn transmittance(
        &self,
        p0: Vec3,
        n0: Vec3,
        p1: Vec3,
        n1: Vec3,
        medium: Option<u32>,
    ) -> Rgb {
        if !self.has_media() {
            return if self.occluded(p0, n0, p1, n1) {
                Rgb::ZERO
            } else {
                Rgb::ONE
            };
        }
        let d = p1 - p0;
        let from = if n0 == Vec3::ZERO {
            p0
        } else {
            offset_origin(p0, n0, d)
        };
        let to = if n1 == Vec3::ZERO {
            p1
        } else {
            offset_origin(p1, n1, -d)
        };
        let seg = to - from;
        let dist = seg.length();
        if dist <= 0.0 || seg.dot(d) <= 0.0 {
            return self.transmittance_over(medium, p0.distance(p1));
        }
        // One traversal of the segment: it stops at the first blocker, and collects the null
        // boundaries crossed (a sphere may be crossed twice); they are then walked in order.
        let ray = Ray::new(from, seg / dist);
        let mut crossings = [(0.0f32, 0u32); MAX_COLLECTED_CROSSINGS];
        let mut n = 0;
        let mut overflow = false;
        let blocked = self.accel.visit(&ray, dist, |i, prim| {
            let material = &self.materials[self.objects[prim.object as usize].material as usize];
            if !material.value.is_null() {
                return prim.shape.intersect(&ray, dist).is_some();
            }
            for t in segment_crossings(&prim.shape, &ray, dist)
                .into_iter()
                .flatten()
            {
                if n < crossings.len() {
                    crossings[n] = (t, i);
                    n += 1;
                } else {
                    overflow = true;
                }
            }
            false
        });
        if blocked {
            return Rgb::ZERO;
        }
        if overflow {
            return self.transmittance_walk(p0, p1, from, to, medium);
        }
        let crossings = &mut crossings[..n];
        crossings.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        let prims = self.accel.primitives();
        let mut tr = Rgb::ONE;
        let mut medium = medium;
        // Distances are measured from the end points themselves, not the offset origins.
        let mut last = p0;
        for &(t, i) in crossings.iter() {
            let p = ray.at(t);
            tr *= self.transmittance_over(medium, p.distance(last));
            last = p;
            let hit = Hit {
                t,
                p,
                ng: prims[i as usize].shape.normal(p),
                prim: i,
            };
            medium = self.medium_after(&hit, ray.dir, medium);
        }
        tr * self.transmittance_over(medium, p1.distance(last))
    }

    /// exp(-sigma_t d) in `medium` (one in vacuum).
    fn transmittance_over(&self, medium: Option<u32>, d: f32) -> Rgb {
        match medium {
            Some(m) => self.media[m as usize].value.transmittance_over(d),
            None => Rgb::ONE,
        }
    }

    /// [`Scene::transmittance`] by closest hits, one boundary after another: for segments
    /// that cross more boundaries than one traversal collects.
    fn transmittance_walk(
        &self,
        p0: Vec3,
        p1: Vec3,
        from: Vec3,
        to: Vec3,
        medium: Option<u32>,
    ) -> Rgb {
        let d = p1 - p0;
        let tr_over = |medium: Option<u32>, d: f32| self.transmittance_over(medium, d);
        let mut tr = Rgb::ONE;
        let mut medium = medium;
        let mut origin = from;
        let mut last = p0;
        for _ in 0..MAX_BOUNDARY_CROSSINGS {
            let seg = to - origin;
            let dist = seg.length();
            if dist <= 0.0 || seg.dot(d) <= 0.0 {
                break;
            }
            let ray = Ray::new(origin, seg / dist);
            let Some(hit) = self.intersect(&ray, dist) else {
                break;
            };
            if !self.material(&hit).is_null() {
                return Rgb::ZERO;
            }
            tr *= tr_over(medium, hit.p.distance(last));
            if tr == Rgb::ZERO {
                return tr;
            }
            last = hit.p;
            medium = self.medium_after(&hit, ray.dir, medium);
            origin = offset_origin(hit.p, hit.ng, ray.dir);
        }
        tr * tr_over(medium, p1.distance(last))
    }

    /// Whether the segment between two surface points is blocked by anything but null
    /// boundaries. The ends are offset along their normals (a zero normal: no offset).
    pub fn occluded(&self, p0: Vec3, n0: Vec3, p1: Vec3, n1: Vec3) -> bool {
        let d = p1 - p0;
        let from = if n0 == Vec3::ZERO {
            p0
        } else {
            offset_origin(p0, n0, d)
        };
        let to = if n1 == Vec3::ZERO {
            p1
        } else {
            offset_origin(p1, n1, -d)
        };
        let seg = to - from;
        let dist = seg.length();
        if dist <= 0.0 {
            return false;
        }
        let ray = Ray::new(from, seg / dist);
        let prims_objects = &self.objects;
        let materials = &self.materials;
        self.accel.occluded(&ray, dist, |prim| {
            !materials[prims_objects[prim.object as usize].material as usize]
                .value
                .is_null()
        })
    }

    /// Samples a light proportionally to power: (index, probability).
    #[inline]
    pub fn sample_light(&self, u: f32) -> Option<(usize, f32)> {
        if self.lights.is_empty() || self.light_distribution.total() <= 0.0 {
            return None;
        }
        Some(self.light_distribution.sample(u))
    }

    /// Probability of choosing light `i`.
    #[inline]
    pub fn light_pmf(&self, i: usize) -> f32 {
        self.light_distribution.pmf(i)
    }

    /// Total emitted power of all lights (W).
    pub fn total_power(&self) -> Rgb {
        self.lights.iter().map(|l| l.power()).sum()
    }

    /// Whether any participating medium is used. Cheap (every shadow ray asks): a shape with
    /// an `interior` is closed, so it is among the volumes, which exist only when media do.
    #[inline]
    pub fn has_media(&self) -> bool {
        self.medium.is_some() || !self.volumes.is_empty()
    }
}

/// An object that bounds a volume, with what point-in-volume tests need.
struct Volume {
    object: u32,
    /// Its primitives (indices into the BVH's primitives).
    prims: Vec<u32>,
    /// Its bounding box.
    lo: Vec3,
    hi: Vec3,
}

/// Null boundaries a shadow ray may cross before it is taken as blocked (guards against rays
/// stuck on coincident boundaries).
const MAX_BOUNDARY_CROSSINGS: u32 = 256;

/// Null-boundary crossings one traversal of a shadow ray collects; more, and it walks them
/// one closest hit at a time.
const MAX_COLLECTED_CROSSINGS: usize = 16;

/// Where a ray crosses a shape within (0, tmax): both roots of a sphere, the one point of a
/// quad or triangle.
fn segment_crossings(shape: &Shape, ray: &Ray, tmax: f32) -> [Option<f32>; 2] {
    match *shape {
        Shape::Sphere { center, radius } => {
            // As Shape::intersect (Ray Tracing Gems ch. 7), keeping both roots.
            let f = ray.origin - center;
            let b = -f.dot(ray.dir);
            let l = f + b * ray.dir;
            let disc = radius * radius - l.dot(l);
            if disc < 0.0 {
                return [None, None];
            }
            let c = f.dot(f) - radius * radius;
            let q = b + b.signum() * disc.sqrt();
            if q == 0.0 {
                return [None, None];
            }
            let inside = |t: f32| (t > 0.0 && t < tmax).then_some(t);
            [inside(c / q), inside(q)]
        }
        _ => [shape.intersect(ray, tmax), None],
    }
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
        Shape::Sphere { center, radius } => (p.distance(center) - radius).abs(),
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
        None => Vec3::ZERO,
    }
}

/// Which objects bound volumes, and their medium interfaces. A closed shape bounds a volume
/// if it has an `interior` medium, or if light can enter it (a null or dielectric material):
/// then its inside is vacuum (clear glass in fog). Opaque shapes without an interior leave
/// the medium as it is (light reflected there stays on its side).
fn medium_interfaces(
    objects: &[Object],
    materials: &[Named<Material>],
    accel: &Accel,
    scene_medium: Option<u32>,
) -> (Vec<Option<MediumInterface>>, Vec<Volume>, Vec<bool>) {
    let mut index = vec![None; objects.len()];
    let mut volumes: Vec<Volume> = Vec::new();
    for (i, o) in objects.iter().enumerate() {
        let m = &materials[o.material as usize].value;
        if o.closed
            && (o.interior.is_some() || m.is_null() || matches!(m, Material::Dielectric { .. }))
        {
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
    let mut out = vec![None; objects.len()];
    for (k, volume) in volumes.iter().enumerate() {
        let parent = containers[k].iter().copied().max_by_key(|&c| depth[c]);
        let i = volume.object as usize;
        out[i] = Some(MediumInterface {
            inside: objects[i].interior,
            outside: parent.map_or(scene_medium, |c| {
                objects[volumes[c].object as usize].interior
            }),
            depth: depth[k],
        });
    }
    let mut alone = vec![false; objects.len()];
    let pad = |v: &Volume| 1e-3 * (1.0 + v.lo.abs().max(v.hi.abs()).max_element());
    for (k, v) in volumes.iter().enumerate() {
        alone[v.object as usize] = volumes.iter().enumerate().all(|(c, w)| {
            let e = pad(v).max(pad(w));
            c == k || (v.lo - e).cmpgt(w.hi).any() || (w.lo - e).cmpgt(v.hi).any()
        });
    }
    (out, volumes, alone)
}

/// See [`Scene::medium_at`].
fn locate_medium(
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

fn undefined(kind: &str, name: &str, known: &HashMap<String, u32>) -> String {
    let mut names: Vec<&str> = known.keys().map(String::as_str).collect();
    names.sort();
    if names.is_empty() {
        {
            let plural = if kind == "medium" {
                "media"
            } else {
                "materials"
            };
            format!("{kind} {name:?} is not defined (no {plural} are defined)")
        }
    } else {
        format!(
            "{kind} {name:?} is not defined; defined: {}",
            names.join(", ")
        )
    }
}

fn read_render(root: &Properties<'_>, ld: &mut Loader) -> Result<RenderSettings> {
    let t = root
        .table("render")?
        .unwrap_or_else(|| Properties::empty(root.file(), "render"));
    let integrator = t.string("integrator", "path")?.to_string();
    let spp = t.u32("spp", 16)?;
    if spp == 0 {
        return Err(t.error("spp", "must be at least 1"));
    }
    let settings = RenderSettings {
        integrator,
        spp,
        seed: t.u64("seed", 0)?,
        max_depth: t.u32("max_depth", 16)?,
    };
    ld.done(&t);
    Ok(settings)
}

fn read_film(root: &Properties<'_>, ld: &mut Loader) -> Result<FilmSettings> {
    let t = root
        .table("film")?
        .unwrap_or_else(|| Properties::empty(root.file(), "film"));
    let width = t.u32("width", 256)?;
    let height = t.u32("height", 256)?;
    for (k, v) in [("width", width), ("height", height)] {
        if v == 0 || v > 1 << 15 {
            return Err(t.error(k, format!("must be between 1 and 32768, found {v}")));
        }
    }
    let output = t.string("output", "out.exr")?;
    let out = PathBuf::from(output);
    crate::film::format_of(&out).map_err(|_| {
        t.error(
            "output",
            format!("{output:?}: unsupported format; expected a .exr or .png file name"),
        )
    })?;
    let film = FilmSettings {
        width,
        height,
        output: ld.dir.join(out),
    };
    ld.done(&t);
    Ok(film)
}

fn read_camera(root: &Properties<'_>, film: &FilmSettings, ld: &mut Loader) -> Result<Camera> {
    let Some(t) = root.table("camera")? else {
        return Err(root.error(
            "camera",
            "missing section [camera]; expected position, look_at, up, fov",
        ));
    };
    let position = t.vec3_required("position")?;
    let look_at = t.vec3_required("look_at")?;
    let up = t.vec3("up", Vec3::Y)?;
    let fov = t.f32("fov", 39.3)?;
    if !(fov > 0.0 && fov < 180.0) {
        return Err(t.error("fov", format!("must be in (0, 180) degrees, found {fov}")));
    }
    let forward = look_at - position;
    if forward.length_squared() == 0.0 {
        return Err(t.error("look_at", "is the same point as position"));
    }
    if forward.normalize().cross(up).length_squared() < 1e-12 {
        return Err(t.error("up", "is zero or parallel to the viewing direction"));
    }
    ld.done(&t);
    Ok(Camera::new(
        position,
        look_at,
        up,
        fov,
        film.width,
        film.height,
    ))
}

type Index = HashMap<String, u32>;

fn read_materials(root: &Properties<'_>, ld: &mut Loader) -> Result<(Vec<Named<Material>>, Index)> {
    let mut out = Vec::new();
    let mut index = HashMap::new();
    let Some(all) = root.table("materials")? else {
        return Ok((out, index));
    };
    let names: Vec<&str> = all.keys().collect();
    for name in names {
        let m = all.table(name)?.unwrap();
        let ty = m.string_opt("type")?.ok_or_else(|| {
            m.error(
                "type",
                format!("missing; expected one of: {}", MATERIAL_TYPES.join(", ")),
            )
        })?;
        let material = match ty {
            "diffuse" => {
                let reflectance = m.rgb("reflectance", Rgb::splat(0.5))?;
                if reflectance.max_element() > 1.0 {
                    ld.warn(
                        &m,
                        "reflectance",
                        "is above 1: the material creates energy".into(),
                    );
                }
                Material::Diffuse { reflectance }
            }
            "mirror" => {
                let reflectance = m.rgb("reflectance", Rgb::ONE)?;
                if reflectance.max_element() > 1.0 {
                    ld.warn(
                        &m,
                        "reflectance",
                        "is above 1: the material creates energy".into(),
                    );
                }
                Material::Mirror { reflectance }
            }
            "dielectric" => {
                let ior = m.f32("ior", 1.5)?;
                if ior <= 0.0 {
                    return Err(m.error("ior", format!("must be positive, found {ior}")));
                }
                Material::Dielectric { ior }
            }
            "null" => Material::Null,
            other => {
                return Err(m.error(
                    "type",
                    format!(
                        "unknown material type {other:?}; expected one of: {}",
                        MATERIAL_TYPES.join(", ")
                    ),
                ));
            }
        };
        index.insert(name.to_string(), out.len() as u32);
        out.push(Named {
            name: name.to_string(),
            value: material,
        });
        ld.done(&m);
    }
    ld.done(&all);
    Ok((out, index))
}

fn read_media(root: &Properties<'_>, ld: &mut Loader) -> Result<(Vec<Named<Homogeneous>>, Index)> {
    let mut out = Vec::new();
    let mut index = HashMap::new();
    let Some(all) = root.table("media")? else {
        return Ok((out, index));
    };
    let names: Vec<&str> = all.keys().collect();
    for name in names {
        let m = all.table(name)?.unwrap();
        let ty = m.string_opt("type")?.ok_or_else(|| {
            m.error(
                "type",
                format!("missing; expected one of: {}", MEDIUM_TYPES.join(", ")),
            )
        })?;
        if ty != "homogeneous" {
            return Err(m.error(
                "type",
                format!(
                    "unknown medium type {ty:?}; expected one of: {}",
                    MEDIUM_TYPES.join(", ")
                ),
            ));
        }
        let sigma_a = m.rgb("sigma_a", Rgb::ZERO)?;
        let sigma_s = m.rgb("sigma_s", Rgb::ZERO)?;
        let phase = match m.node("phase").map(|n| &n.value) {
            None => Phase::Isotropic,
            Some(Value::Str(s)) if s == "isotropic" => Phase::Isotropic,
            Some(Value::Str(s)) => {
                return Err(m.error(
                    "phase",
                    format!("unknown phase function {s:?}; expected \"isotropic\" or {{ type = \"hg\", g = ... }}"),
                ));
            }
            Some(Value::Table(_)) => {
                let p = m.table("phase")?.unwrap();
                let ty = p.choice("type", &["hg", "isotropic"], "hg")?;
                let phase = if ty == "isotropic" {
                    Phase::Isotropic
                } else {
                    let g = p.f32("g", 0.0)?;
                    if g.abs() >= 1.0 {
                        return Err(p.error("g", format!("must satisfy |g| < 1, found {g}")));
                    }
                    Phase::HenyeyGreenstein { g }
                };
                ld.done(&p);
                phase
            }
            Some(other) => {
                return Err(m.error(
                    "phase",
                    format!(
                        "expected \"isotropic\" or {{ type = \"hg\", g = ... }}, found {} `{}`",
                        other.type_name(),
                        other.show()
                    ),
                ));
            }
        };
        index.insert(name.to_string(), out.len() as u32);
        out.push(Named {
            name: name.to_string(),
            value: Homogeneous {
                sigma_a,
                sigma_s,
                phase,
            },
        });
        ld.done(&m);
    }
    ld.done(&all);
    Ok((out, index))
}

/// The `[[shapes]]` or `[[lights]]` array: (key path, bag) per element.
fn array_of_tables<'a>(root: &Properties<'a>, key: &str) -> Result<Vec<Properties<'a>>> {
    let Some(node) = root.node(key) else {
        return Ok(Vec::new());
    };
    let Value::Array(items) = &node.value else {
        return Err(root.error(
            key,
            format!(
                "expected an array of tables ([[{key}]]), found {}",
                node.value.type_name()
            ),
        ));
    };
    items
        .iter()
        .enumerate()
        .map(|(i, item)| Properties::new(root.file(), &format!("{key}[{i}]"), item))
        .collect()
}

fn read_transform(s: &Properties<'_>, ld: &mut Loader) -> Result<Mat4> {
    let Some(t) = s.table("transform")? else {
        return Ok(Mat4::IDENTITY);
    };
    let translate = t.vec3("translate", Vec3::ZERO)?;
    let scale = match t.node("scale").map(|n| &n.value) {
        None => Vec3::ONE,
        Some(Value::Array(_)) => t.vec3_required("scale")?,
        Some(_) => Vec3::splat(t.f32_required("scale")?),
    };
    if scale.x * scale.y * scale.z == 0.0 {
        return Err(t.error("scale", "must not be zero"));
    }
    let rotate = match t.table("rotate")? {
        None => Mat4::IDENTITY,
        Some(r) => {
            let axis = r.vec3_required("axis")?;
            if axis.length_squared() == 0.0 {
                return Err(r.error("axis", "must not be the zero vector"));
            }
            let degrees = r.f32_required("degrees")?;
            ld.done(&r);
            Mat4::from_axis_angle(axis.normalize(), degrees.to_radians())
        }
    };
    ld.done(&t);
    Ok(Mat4::from_translation(translate) * rotate * Mat4::from_scale(scale))
}

/// The mesh's triangles, and whether it is closed.
fn load_obj(s: &Properties<'_>, path: &Path, transform: Mat4) -> Result<(Vec<Shape>, bool)> {
    if path.exists() && !path.is_file() {
        return Err(s.error(
            "file",
            format!("mesh {} is not a regular file", path.display()),
        ));
    }
    let file = std::fs::File::open(path)
        .map_err(|e| s.error("file", format!("cannot open mesh {}: {e}", path.display())))?;
    let mut reader = std::io::BufReader::new(file);
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ..Default::default()
    };
    // Material libraries are not followed: materials come from the scene file.
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| s.error("file", format!("{}: malformed OBJ: {e}", path.display())))?;
    let mirrored = transform.determinant() < 0.0;
    let mut tris = Vec::new();
    let mut corners = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let positions: Vec<Vec3> = mesh
            .positions
            .chunks_exact(3)
            .map(|p| transform.transform_point3(Vec3::new(p[0], p[1], p[2])))
            .collect();
        for face in mesh.indices.chunks_exact(3) {
            let mut v = [Vec3::ZERO; 3];
            for (slot, &i) in v.iter_mut().zip(face) {
                *slot = *positions.get(i as usize).ok_or_else(|| {
                    s.error(
                        "file",
                        format!(
                            "{}: face index {} out of range ({} vertices)",
                            path.display(),
                            i + 1,
                            positions.len()
                        ),
                    )
                })?;
            }
            if mirrored {
                // A mirroring transform reverses the winding; undo it so that normals keep
                // their side (outward stays outward).
                v.swap(1, 2);
            }
            if !v.iter().all(|p| p.is_finite()) {
                return Err(s.error("file", format!("{}: non-finite vertex", path.display())));
            }
            let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
            if e1.cross(e2).length_squared() > 0.0 {
                tris.push(Shape::Triangle { p0: v[0], e1, e2 });
                corners.push(v);
            }
        }
    }
    if tris.is_empty() {
        return Err(s.error(
            "file",
            format!("{}: the mesh has no triangles", path.display()),
        ));
    }
    Ok((tris, is_closed(&corners)))
}

/// A closed (watertight), consistently oriented triangle set: every directed edge is used by
/// exactly one triangle and its reverse by exactly one other. Needed for `interior`: inside
/// and outside must be well defined. Vertices are matched by position (+0 and -0 alike).
pub fn is_closed(tris: &[[Vec3; 3]]) -> bool {
    type Vertex = (u32, u32, u32);
    // Adding +0.0 turns -0.0 into +0.0.
    let key = |p: Vec3| -> Vertex {
        let p = p + Vec3::ZERO;
        (p.x.to_bits(), p.y.to_bits(), p.z.to_bits())
    };
    let mut directed: HashMap<(Vertex, Vertex), u32> = HashMap::new();
    for v in tris {
        for i in 0..3 {
            *directed
                .entry((key(v[i]), key(v[(i + 1) % 3])))
                .or_default() += 1;
        }
    }
    !directed.is_empty()
        && directed
            .iter()
            .all(|(&(a, b), &n)| n == 1 && directed.get(&(b, a)) == Some(&1))
}

#[allow(clippy::too_many_arguments)]
fn read_shapes(
    root: &Properties<'_>,
    ld: &mut Loader,
    material_defs: &[Named<Material>],
    materials: &Index,
    media: &Index,
    objects: &mut Vec<Object>,
    prims: &mut Vec<Primitive>,
    lights: &mut Vec<Light>,
) -> Result<()> {
    for s in array_of_tables(root, "shapes")? {
        let ty = s.string_opt("type")?.ok_or_else(|| {
            s.error(
                "type",
                format!("missing; expected one of: {}", SHAPE_TYPES.join(", ")),
            )
        })?;
        let mut closed = ty == "sphere";
        let shapes = match ty {
            "sphere" => {
                let center = s.vec3_required("center")?;
                let radius = s.f32_required("radius")?;
                if radius <= 0.0 {
                    return Err(s.error("radius", format!("must be positive, found {radius}")));
                }
                vec![Shape::Sphere { center, radius }]
            }
            "quad" => {
                let origin = s.vec3_required("origin")?;
                let u = s.vec3_required("u")?;
                let v = s.vec3_required("v")?;
                if u.cross(v).length_squared() == 0.0 {
                    return Err(
                        s.error("v", "u and v are parallel or zero: the quad has zero area")
                    );
                }
                vec![Shape::quad(origin, u, v)]
            }
            "mesh" => {
                let file = s.string_required("file")?;
                let transform = read_transform(&s, ld)?;
                let (tris, is_closed) = load_obj(&s, &ld.dir.join(file), transform)?;
                closed = is_closed;
                tris
            }
            other => {
                return Err(s.error(
                    "type",
                    format!(
                        "unknown shape type {other:?}; expected one of: {}",
                        SHAPE_TYPES.join(", ")
                    ),
                ));
            }
        };
        let material_name = s.string_required("material")?;
        let material = *materials
            .get(material_name)
            .ok_or_else(|| s.error("material", undefined("material", material_name, materials)))?;
        let interior = match s.string_opt("interior")? {
            None => None,
            Some(name) => {
                let id = *media
                    .get(name)
                    .ok_or_else(|| s.error("interior", undefined("medium", name, media)))?;
                if !closed {
                    return Err(s.error(
                        "interior",
                        format!("a {ty} that is not closed cannot have an interior medium (a mesh needs every edge shared by exactly two consistently oriented triangles)"),
                    ));
                }
                Some(id)
            }
        };
        let object = objects.len() as u32;
        let mut light = None;
        if let Some(emission) = s.rgb_opt("emission")?
            && emission.max_element() > 0.0
        {
            if material_defs[material as usize].value.is_null() {
                return Err(s.error(
                    "emission",
                    "a shape with the null material is invisible and cannot emit; give it a real material (e.g. a black diffuse one)",
                ));
            }
            light = Some(lights.len() as u32);
            lights.push(area_light(shapes.clone(), emission, object));
        }
        objects.push(Object {
            name: s.path().to_string(),
            material,
            light,
            interior,
            closed,
        });
        prims.extend(shapes.into_iter().map(|shape| Primitive { shape, object }));
        ld.done(&s);
    }
    Ok(())
}

fn read_point_lights(
    root: &Properties<'_>,
    ld: &mut Loader,
    lights: &mut Vec<Light>,
) -> Result<()> {
    for l in array_of_tables(root, "lights")? {
        let ty = l.string_opt("type")?.ok_or_else(|| {
            l.error(
                "type",
                format!("missing; expected one of: {}", LIGHT_TYPES.join(", ")),
            )
        })?;
        if ty != "point" {
            return Err(l.error(
                "type",
                format!(
                    "unknown light type {ty:?}; expected one of: {}",
                    LIGHT_TYPES.join(", ")
                ),
            ));
        }
        let position = l.vec3_required("position")?;
        let intensity = match (l.rgb_opt("intensity")?, l.rgb_opt("power")?) {
            (Some(i), None) => i,
            (None, Some(p)) => p / (4.0 * std::f32::consts::PI),
            (Some(_), Some(_)) => {
                return Err(l.error(
                    "power",
                    "give either intensity (W/sr) or power (W), not both",
                ));
            }
            (None, None) => {
                return Err(l.error(
                    "intensity",
                    "missing; expected intensity = [r, g, b] (W/sr) or power = [r, g, b] (W)",
                ));
            }
        };
        lights.push(Light::Point {
            position,
            intensity,
        });
        ld.done(&l);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_is_closed_and_open_box_is_not() {
        let c = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
        let quads = [
            (c(0., 0., 0.), c(0., 1., 0.), c(1., 0., 0.)),
            (c(0., 0., 1.), c(1., 0., 0.), c(0., 1., 0.)),
            (c(0., 0., 0.), c(1., 0., 0.), c(0., 0., 1.)),
            (c(0., 1., 0.), c(0., 0., 1.), c(1., 0., 0.)),
            (c(0., 0., 0.), c(0., 0., 1.), c(0., 1., 0.)),
            (c(1., 0., 0.), c(0., 1., 0.), c(0., 0., 1.)),
        ];
        let mut tris = Vec::new();
        for (o, u, v) in quads {
            tris.push([o, o + u, o + u + v]);
            tris.push([o, o + u + v, o + v]);
        }
        assert!(is_closed(&tris));
        tris.pop();
        assert!(!is_closed(&tris));
    }
}
