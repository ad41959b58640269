//! The scene: what a scene file describes, as the integrators use it, and the queries they
//! make of it (closest hits, materials, lights). The rest of it, one concept per file:
//! [`volumes`] (which medium is where, from how closed shapes nest) and [`visibility`]
//! (shadow rays, through null boundaries and media). Reading scene files (TOML, Mitsuba XML,
//! meshes, images) is not core's: foton-loader reads them and hands [`Scene::new`] the parts.

mod alpha;
mod visibility;
mod volumes;

pub use volumes::MediumInterface;
use volumes::Volume;

use crate::Rgb;
use crate::accel::Accel;
use crate::bsdf::{Bsdf, Frame, LightTerms};
use crate::camera::Camera;
use crate::error::{Location, Result};
use crate::film::{DisplayTransform, ToneMap};
use crate::geometry::{Hit, Primitive, Ray, SurfacePoint, TriangleAttrs};
use crate::light::Light;
use crate::material::diffuse::{DiffuseBxdf, DiffuseMaterial};
use crate::material::{Lobe, Material};
use crate::medium::Medium;
use crate::props::Properties;
use crate::props::Unused;
use crate::sampling::Distribution1D;
use crate::texture::Texture;
use crate::value::{Document, Value};
use glam::Vec3;
use std::path::{Path, PathBuf};
use volumes::{locate_medium, medium_interfaces};

#[derive(Clone, Debug)]
pub struct RenderSettings {
    /// Name of the integrator plugin.
    pub integrator: String,
    /// Camera samples per pixel.
    pub spp: u32,
    pub seed: u64,
    /// Scattering events, pbrt style: 0 = emitters seen directly, 1 = direct lighting.
    pub max_depth: u32,
    /// Emitters (area lights, the environment) are not seen directly by the camera: camera
    /// rays pass through them until they first scatter (Mitsuba's `hide_emitters`).
    pub hide_emitters: bool,
    /// The points camera samples draw (`[render] sampler`, and `jitter` for `stratified`).
    pub sampler: crate::sampling::SamplerKind,
    /// A time limit in seconds (Mitsuba's `timeout`): the host renders the camera samples, or
    /// a progressive integrator's iterations, that fill it, at most `spp`. Integrators render
    /// `spp` and do not read it.
    pub time: Option<f32>,
}

#[derive(Clone, Debug)]
pub struct FilmSettings {
    pub width: u32,
    pub height: u32,
    /// Resolved against the scene file's folder.
    pub output: PathBuf,
    /// Stops by which 8-bit outputs (PNG) scale the radiance: x 2^exposure. EXR ignores it.
    pub exposure: f32,
    /// How 8-bit outputs fit the exposed radiance into [0, 1]. EXR ignores it.
    pub tonemap: ToneMap,
    /// The pixel filter, as camera samples are placed with it (filter importance sampling).
    pub filter: crate::filter::FilterSampler,
    /// The colour temperature (K) rendered white (pbrt-v4's `whitebalance`); None: none.
    pub white_balance: Option<f32>,
}

impl FilmSettings {
    /// The camera's response the film applies to each pixel ([`crate::film::Film::color_matrix`]).
    pub fn color_matrix(&self) -> Option<glam::DMat3> {
        self.white_balance
            .map(|k| crate::spectrum::white_balance(k as f64))
    }

    /// The transform from radiance to the display values of a PNG.
    pub fn display(&self) -> DisplayTransform {
        DisplayTransform::new(self.exposure, self.tonemap)
    }
}

/// What a primitive belongs to: a `[[shapes]]` entry.
#[derive(Clone, Debug)]
pub struct Object {
    /// "shapes[3]" (its key path) for messages.
    pub name: String,
    pub material: u32,
    /// The area light this object is, if it emits.
    pub light: Option<u32>,
    /// Medium inside the shape (behind its normal).
    pub interior: Option<u32>,
    /// Medium outside the shape (on its normal's side), when the file names it.
    pub exterior: Option<u32>,
    /// Whether the file names both sides (`exterior` given: Mitsuba's interior and exterior,
    /// None being vacuum): the shape is a medium interface as written, open or closed, and
    /// nothing about it is inferred.
    pub explicit_media: bool,
    /// Whether the shape is closed (a sphere, a watertight consistently oriented mesh). The
    /// loader finds it out only for a shape that may bound a medium (media named, a null or
    /// volume-enclosing material) and says false for the others, which bound no volume.
    pub closed: bool,
    /// The shape's cut-out (pbrt-v4's `alpha`, Mitsuba's `mask`): where the texture's value
    /// (a colour's luminance) is 0 the shape is absent, where it is 1 present, and between
    /// present with that probability (see [`Scene::intersect`]). None: opaque everywhere.
    pub alpha: Option<Texture>,
    /// The shading normals of its material's `normal_map` (Mitsuba's `normalmap`, pbrt-v4's
    /// `normalmap`): a texture whose colour c gives the normal 2c - 1 in the surface's
    /// shading frame (x along dp/du, z the normal). None: the surface's own normals.
    pub normal_map: Option<Texture>,
    /// Its material's bump map (Mitsuba's `bumpmap`, pbrt-v4's `displacement`). At most one
    /// of `normal_map` and `bump_map` is given.
    pub bump_map: Option<BumpMap>,
    /// What the map does to the light's side of the BSDF (see [`LightTerms`]).
    pub map_light: MapLight,
}

/// Which of Mitsuba's [`LightTerms`] a normal or bump map brings: none (pbrt-v4, and
/// foton's default), the cut-off of light from below the surface's own normal (Mitsuba 0.6),
/// or that and the shadowing term (Mitsuba 3's default).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MapLight {
    pub cut_off: bool,
    pub shadowing: bool,
}

/// A height field over a surface's texture coordinates that tilts its shading normal: the
/// surface p + h(u, v) n, whose normal, the usually negligible derivative of n left out (as
/// Mitsuba's `bumpmap` leaves it out), is (dp/du + h_u n) x (dp/dv + h_v n) with h the
/// texture's value (a colour's luminance) times `scale`.
#[derive(Clone, Debug)]
pub struct BumpMap {
    pub height: Texture,
    pub scale: f32,
}

/// A medium of any kind.
pub type BoxedMedium = Box<dyn Medium>;

/// A named material or medium, as referenced from shapes.
#[derive(Clone, Debug)]
pub struct Named<T> {
    pub name: String,
    pub value: T,
}

pub struct Scene {
    pub(crate) file: PathBuf,
    pub(crate) render: RenderSettings,
    pub(crate) film: FilmSettings,
    pub(crate) camera: Camera,
    pub(crate) materials: Vec<Named<Material>>,
    /// The media, each behind the `Medium` interface (a new kind is one implementation).
    pub(crate) media: Vec<Named<BoxedMedium>>,
    pub(crate) objects: Vec<Object>,
    pub(crate) lights: Vec<Light>,
    /// Chooses a light proportionally to its power.
    pub(crate) light_distribution: Distribution1D,
    /// The environment light (`constant`), seen by rays that leave the scene.
    pub(crate) environment: Option<u32>,
    pub(crate) accel: Accel,
    /// Vertex normals and texture coordinates of mesh triangles (`Primitive::attrs`).
    pub(crate) triangle_attrs: Vec<TriangleAttrs>,
    /// The mesh attribute of each triangle's corners, indexed as `triangle_attrs` (empty when
    /// no material reads one; zero for triangles of meshes that carry none).
    pub(crate) triangle_attributes: Vec<[Rgb; 3]>,
    /// The medium filling free space, if any.
    pub(crate) medium: Option<u32>,
    /// Per object: its medium interface if it bounds a volume (see [`MediumInterface`]); all
    /// None in a scene without media.
    pub(crate) interfaces: Vec<Option<MediumInterface>>,
    /// The medium around the camera (None: vacuum): the camera's `medium`, or the one found
    /// where it stands.
    pub(crate) camera_medium: Option<u32>,
    /// Whether any medium is used (see [`Scene::has_media`]).
    has_media: bool,
    /// Whether any object has a cut-out (its `alpha`): only then do ray queries test them.
    has_alpha: bool,
    /// Whether any object has a normal or a bump map: only then does [`Scene::bsdf`] look
    /// for one.
    has_normal_maps: bool,
    /// Per light: the medium the file puts it in (a point or spot light's `medium`, an area
    /// light whose shape names its exterior); None: found from where it lies.
    light_media: Vec<Option<Option<u32>>>,
    /// The objects that bound volumes, for [`Scene::medium_at`].
    volumes: Vec<Volume>,
    /// Per object: a volume whose bounding box meets no other volume's, so that no other
    /// boundary can coincide with it and crossing it needs no search for coincident ones.
    alone: Vec<bool>,
    /// Axis-aligned bounds of all geometry and point lights.
    pub(crate) bounds: (Vec3, Vec3),
    /// The parsed document (integrators read their `[integrators.NAME]` table from it).
    pub(crate) document: Document,
    /// The files the scene read besides its own (meshes), in the order it read them.
    pub(crate) sources: Vec<PathBuf>,
    /// Keys that were present but never read by the loader (not counting `[integrators]`).
    pub(crate) unused: Vec<crate::props::Unused>,
    /// Non-fatal problems (reflectance above one, no lights...).
    pub(crate) warnings: Vec<String>,
    /// Parameters of a Mitsuba file foton understands but ignores, each with its file:line:
    /// warnings, or errors with `--strict`.
    pub(crate) ignored: Vec<String>,
}

/// What a scene file describes, as the loader read it: the parts [`Scene::new`] builds a scene
/// from (the BVH, the light distribution and the medium interfaces are core's work).
pub struct SceneParts {
    pub file: PathBuf,
    pub render: RenderSettings,
    pub film: FilmSettings,
    pub camera: Camera,
    /// The medium the file puts the camera in (`Some(None)`: vacuum); None: found from where
    /// it stands.
    pub camera_medium: Option<Option<u32>>,
    pub materials: Vec<Named<Material>>,
    pub media: Vec<Named<BoxedMedium>>,
    pub objects: Vec<Object>,
    pub primitives: Vec<Primitive>,
    pub triangle_attrs: Vec<TriangleAttrs>,
    /// The mesh attribute at each triangle's corners, as [`Scene`] keeps it.
    pub triangle_attributes: Vec<[Rgb; 3]>,
    pub lights: Vec<Light>,
    /// Per light: the medium the file puts it in (None: found from where it lies).
    pub light_media: Vec<Option<Option<u32>>>,
    /// The medium filling free space, if any.
    pub medium: Option<u32>,
    pub document: Document,
    pub sources: Vec<PathBuf>,
    pub unused: Vec<Unused>,
    pub warnings: Vec<String>,
}

impl Scene {
    /// The scene of `parts`: its bounds, lights fitted to them and their distribution, the
    /// BVH, the medium interfaces and the camera's medium. Err: why the medium around the
    /// camera is undefined (the loader names the camera's line with it).
    #[doc(hidden)]
    pub fn new(parts: SceneParts) -> std::result::Result<Scene, String> {
        let SceneParts {
            file,
            render,
            film,
            camera,
            camera_medium: camera_placed,
            materials,
            media,
            objects,
            primitives: prims,
            triangle_attrs,
            triangle_attributes,
            mut lights,
            light_media,
            medium,
            document,
            sources,
            unused,
            warnings,
        } = parts;
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for p in &prims {
            let b = p.shape.aabb();
            lo = lo.min(b.min.into());
            hi = hi.max(b.max.into());
        }
        for position in lights.iter().filter_map(Light::position) {
            lo = lo.min(position);
            hi = hi.max(position);
        }
        if !lo.is_finite() {
            lo = camera.position;
            hi = camera.position;
        }
        // A light at infinity covers the scene's bounding sphere (the camera included), which
        // its power and photons need.
        let (centre, radius) = {
            let (l, h) = (lo.min(camera.position), hi.max(camera.position));
            (0.5 * (l + h), (0.5 * (h - l).length()).max(1e-3))
        };
        for light in &mut lights {
            light.fit_to_scene(centre, radius);
        }
        let environment = lights
            .iter()
            .position(Light::is_environment)
            .map(|i| i as u32);
        let powers: Vec<f32> = lights.iter().map(|l| crate::average(l.power())).collect();
        let light_distribution = Distribution1D::new(&powers);

        let accel = Accel::build(prims);
        let uses_media = medium.is_some()
            || camera_placed.is_some_and(|m| m.is_some())
            || light_media.iter().any(|m| m.is_some_and(|m| m.is_some()))
            || objects
                .iter()
                .any(|o| o.interior.is_some() || o.exterior.is_some());
        let (interfaces, volumes, alone) = if uses_media {
            medium_interfaces(&objects, &materials, &accel, medium)
        } else {
            (
                vec![None; objects.len()],
                Vec::new(),
                vec![false; objects.len()],
            )
        };
        let mut warnings = warnings;
        if uses_media {
            warnings.extend(volumes::coincident_boundaries(
                &objects,
                &materials,
                &interfaces,
                &accel,
            ));
        }
        let mut camera_medium = camera_placed.flatten();
        if uses_media && camera_placed.is_none() {
            camera_medium = locate_medium(
                &accel,
                &objects,
                &interfaces,
                &volumes,
                medium,
                camera.position,
            )?;
        }
        let has_alpha = objects.iter().any(|o| o.alpha.is_some());
        let has_normal_maps = objects
            .iter()
            .any(|o| o.normal_map.is_some() || o.bump_map.is_some());
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
            environment,
            accel,
            triangle_attrs,
            triangle_attributes,
            medium,
            interfaces,
            volumes,
            alone,
            has_media: uses_media,
            has_alpha,
            has_normal_maps,
            light_media,
            camera_medium,
            bounds: (lo, hi),
            document,
            sources,
            unused,
            warnings,
            ignored: Vec::new(),
        })
    }

    /// The scene file.
    pub fn file(&self) -> &Path {
        &self.file
    }

    /// How to render: the integrator, samples per pixel, seed, path depth, sampler.
    pub fn render(&self) -> &RenderSettings {
        &self.render
    }

    /// The image: size, output, exposure, tone map, pixel filter.
    pub fn film(&self) -> &FilmSettings {
        &self.film
    }

    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The lights, indexed as [`Scene::sample_light`] and [`Scene::area_light`] number them.
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    /// Axis-aligned bounds (min, max) of all geometry and point lights.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    /// The medium around the camera (None: vacuum).
    pub fn camera_medium(&self) -> Option<u32> {
        self.camera_medium
    }

    /// The number of media; [`Scene::medium`] gives each.
    pub fn media_count(&self) -> usize {
        self.media.len()
    }

    /// Where a key path was written in the scene file (line 0: it came from `--set`).
    #[doc(hidden)]
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
    #[doc(hidden)]
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

    /// Closest surface hit (null boundaries included) with t in (0, tmax), past the cut-out
    /// parts of shapes with an `alpha` (at a fractional alpha a, a hit is kept with
    /// probability a, decided by a hash of the ray: the same ray decides the same).
    #[inline]
    pub fn intersect(&self, ray: &Ray, tmax: f32) -> Option<Hit> {
        let hit = self.accel.intersect(ray, tmax);
        if self.has_alpha {
            return self.intersect_past_cut_outs(ray, tmax, hit?);
        }
        hit
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
        self.material_of(self.primitive(hit))
    }

    /// The material of the object `prim` belongs to.
    #[inline]
    pub fn material_of(&self, prim: &Primitive) -> &Material {
        &self.materials[self.objects[prim.object as usize].material as usize].value
    }

    /// The surface at a hit: shading normal, texture coordinates, tangent.
    #[inline]
    pub fn surface(&self, hit: &Hit) -> SurfacePoint {
        self.surface_point(hit, true)
    }

    /// [`Scene::surface`], the coordinates only if asked for (see [`crate::geometry::Shape::surface_at`]); the
    /// geometric normal is the hit's, the one every other query used.
    #[inline]
    fn surface_point(&self, hit: &Hit, coordinates: bool) -> SurfacePoint {
        let prim = self.primitive(hit);
        let attrs = self.triangle_attrs.get(prim.attrs as usize);
        let attribute = self.triangle_attributes.get(prim.attrs as usize);
        prim.shape
            .surface_at(hit.p, hit.ng, attrs, attribute, coordinates)
    }

    /// The BSDF at a hit (None on a null boundary, which does not scatter).
    #[inline]
    pub fn bsdf(&self, hit: &Hit) -> Option<Bsdf> {
        let material = self.material(hit);
        if material.is_null() {
            return None;
        }
        if self.has_normal_maps {
            let object = self.object(hit);
            if object.normal_map.is_some() || object.bump_map.is_some() {
                let mut sp = self.surface(hit);
                let base_n = sp.ns;
                sp.ns = match (&object.normal_map, &object.bump_map) {
                    (Some(map), _) => normal_mapped(&sp, map),
                    (None, Some(bump)) => bumped(&sp, bump),
                    (None, None) => unreachable!(),
                };
                let mut bsdf = material.bsdf(&sp)?;
                if object.map_light.cut_off || object.map_light.shadowing {
                    bsdf.light_terms = LightTerms::new(base_n, sp.ns, object.map_light.shadowing);
                }
                return Some(bsdf);
            }
        }
        let prim = self.primitive(hit);
        let attrs = self.triangle_attrs.get(prim.attrs as usize);
        let flat = attrs.is_none_or(|a| a.normals.is_none());
        // The most common surface of all, a constant diffuse colour, tested for first: the
        // general case below tests the material's kind twice (for its coordinates and for
        // its lobe), each a jump table.
        if flat
            && let Material::Diffuse(DiffuseMaterial {
                reflectance: Texture::Constant(reflectance),
                twosided,
            }) = *material
        {
            return Some(Bsdf {
                lobe: Lobe::Diffuse(DiffuseBxdf {
                    reflectance,
                    twosided,
                }),
                frame: Frame::from_normal(hit.ng),
                ng: hit.ng,
                twosided: false,
                light_terms: LightTerms::NONE,
            });
        }
        let coordinates = material.needs_coordinates();
        // Most hits: no vertex normals, constant colours, an isotropic lobe. The surface point
        // would be the hit's normal and a zero tangent (`Shape::surface_at`), which
        // `flat_bsdf` takes as known.
        if !coordinates && flat {
            return material.flat_bsdf(hit.ng);
        }
        let attribute = self.triangle_attributes.get(prim.attrs as usize);
        material.bsdf(
            &prim
                .shape
                .surface_at(hit.p, hit.ng, attrs, attribute, coordinates),
        )
    }

    /// The area light a hit lies on, if its object emits.
    #[inline]
    pub fn area_light(&self, hit: &Hit) -> Option<(u32, &Light)> {
        let id = self.object(hit).light?;
        Some((id, &self.lights[id as usize]))
    }

    /// Samples a light proportionally to power: (index, probability).
    #[inline]
    pub fn sample_light(&self, u: f32) -> Option<(usize, f32)> {
        if self.lights.is_empty() || self.light_distribution.total() <= 0.0 {
            return None;
        }
        // One light (most test scenes, every Cornell box): no search of the distribution,
        // which was a call per path vertex.
        if self.lights.len() == 1 {
            return Some((0, self.light_distribution.pmf(0)));
        }
        Some(self.light_distribution.sample(u))
    }

    /// Probability of choosing light `i`.
    #[inline]
    pub fn light_pmf(&self, i: usize) -> f32 {
        self.light_distribution.pmf(i)
    }

    /// Radiance arriving along a ray travelling along `dir` that leaves the scene, and the
    /// environment light's index (for MIS).
    #[inline]
    pub fn escaped(&self, dir: Vec3) -> Option<(u32, Rgb)> {
        let id = self.environment?;
        Some((id, self.lights[id as usize].environment(dir)))
    }

    /// Total emitted power of all lights (W).
    pub fn total_power(&self) -> Rgb {
        self.lights.iter().map(|l| l.power()).sum()
    }

    /// Medium `id` (an index into `media`).
    #[inline]
    pub fn medium(&self, id: u32) -> &dyn Medium {
        self.media[id as usize].value.as_ref()
    }

    /// Whether any participating medium is used (by the scene, a shape, the camera or a
    /// light). Cheap: every shadow ray asks.
    #[inline]
    pub fn has_media(&self) -> bool {
        self.has_media
    }

    /// The name of the first medium that emits light, if the scene uses media: integrators
    /// that do not render a medium's emission refuse such a scene with it.
    pub fn emissive_medium(&self) -> Option<&str> {
        if !self.has_media {
            return None;
        }
        self.media
            .iter()
            .find(|m| m.value.is_emissive())
            .map(|m| m.name.as_str())
    }
}

/// The shading normal a normal map gives at a surface point: its colour c as 2c - 1 in the
/// point's shading frame (Mitsuba 3's `normalmap`, pbrt-v4's `NormalMap`), turned to the
/// geometric normal's side; the surface's own where the map gives no direction.
fn normal_mapped(sp: &SurfacePoint, map: &Texture) -> Vec3 {
    let local = 2.0 * map.eval(sp.texture_ctx()) - Vec3::ONE;
    let n = Frame::from_normal_tangent(sp.ns, sp.dpdu)
        .to_world(local)
        .normalize_or_zero();
    if n == Vec3::ZERO {
        return sp.ns;
    }
    if n.dot(sp.ng) < 0.0 { -n } else { n }
}

/// The shading normal a bump map gives at a surface point (see [`BumpMap`]; Mitsuba 3's
/// `bumpmap`), turned to the geometric normal's side; the surface's own where the surface has
/// no tangents.
fn bumped(sp: &SurfacePoint, bump: &BumpMap) -> Vec3 {
    let h = bump.scale * bump.height.gradient(sp.uv);
    let n = sp.ns;
    let dpdu = sp.dpdu + n * (h.x - n.dot(sp.dpdu));
    let dpdv = sp.dpdv + n * (h.y - n.dot(sp.dpdv));
    let b = dpdu.cross(dpdv).normalize_or_zero();
    if b == Vec3::ZERO {
        return sp.ns;
    }
    if b.dot(sp.ng) < 0.0 { -b } else { b }
}

/// What the host (the loader, the tools, the tests) reads and changes of a scene besides what
/// integrators use: not part of the plugin API (`#[doc(hidden)]`, as cargo-semver-checks
/// counts it).
impl Scene {
    #[doc(hidden)]
    pub fn render_mut(&mut self) -> &mut RenderSettings {
        &mut self.render
    }

    #[doc(hidden)]
    pub fn film_mut(&mut self) -> &mut FilmSettings {
        &mut self.film
    }

    #[doc(hidden)]
    pub fn materials(&self) -> &[Named<Material>] {
        &self.materials
    }

    #[doc(hidden)]
    pub fn media(&self) -> &[Named<BoxedMedium>] {
        &self.media
    }

    /// The media, to put another kind of medium in one's place (the tests' media).
    #[doc(hidden)]
    pub fn media_mut(&mut self) -> &mut [Named<BoxedMedium>] {
        &mut self.media
    }

    #[doc(hidden)]
    pub fn objects(&self) -> &[Object] {
        &self.objects
    }

    #[doc(hidden)]
    pub fn accel(&self) -> &Accel {
        &self.accel
    }

    #[doc(hidden)]
    pub fn accel_mut(&mut self) -> &mut Accel {
        &mut self.accel
    }

    /// The medium filling free space, if any.
    #[doc(hidden)]
    pub fn ambient_medium(&self) -> Option<u32> {
        self.medium
    }

    /// Per object: its medium interface if it bounds a volume.
    #[doc(hidden)]
    pub fn interfaces(&self) -> &[Option<MediumInterface>] {
        &self.interfaces
    }

    /// The parsed document (integrators read their `[integrators.NAME]` table from it).
    #[doc(hidden)]
    pub fn document(&self) -> &Document {
        &self.document
    }

    #[doc(hidden)]
    pub fn document_mut(&mut self) -> &mut Document {
        &mut self.document
    }

    /// The files the scene read besides its own (meshes, includes), in the order it read them.
    #[doc(hidden)]
    pub fn sources(&self) -> &[PathBuf] {
        &self.sources
    }

    /// Keys that were present but never read by the loader (not counting `[integrators]`).
    #[doc(hidden)]
    pub fn unused(&self) -> &[Unused] {
        &self.unused
    }

    /// Non-fatal problems (reflectance above one, no lights...).
    #[doc(hidden)]
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Parameters of a Mitsuba file foton understands but ignores, each with its file:line.
    #[doc(hidden)]
    pub fn ignored(&self) -> &[String] {
        &self.ignored
    }

    /// Adds what a reader found besides the document: files it read, warnings, parameters it
    /// ignored.
    #[doc(hidden)]
    pub fn add_report(
        &mut self,
        sources: impl IntoIterator<Item = PathBuf>,
        warnings: impl IntoIterator<Item = String>,
        ignored: impl IntoIterator<Item = String>,
    ) {
        self.sources.extend(sources);
        self.warnings.extend(warnings);
        self.ignored.extend(ignored);
    }
}
