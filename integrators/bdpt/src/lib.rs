//! # `bdpt`: bidirectional path tracer
//!
//! This table is the one list of the parameters (`[integrators.bdpt]`); the README and the
//! scene-format page point here.
//!
//! | parameter  | type    | meaning                                                              | default |
//! |------------|---------|----------------------------------------------------------------------|---------|
//! | `rr_depth` | integer | scattering events of a subpath before Russian roulette may end it    | 5       |
//! | `light_image` | boolean | use the strategies with t = 1 (light paths connected to the camera); `false` leaves them out of the estimate and of the MIS weights (Mitsuba 0.6's `lightImage`) | `true` |
//! | `strategy` | string  | `"s,t"`: render only the strategy with s light and t camera vertices, unweighted (for tests and teaching); `"light"`: only the strategies with t = 1, unweighted (a light tracer); `"all"`: every strategy, weighted by MIS | `"all"` |
//!
//! `[render] max_depth` bounds the scattering events of a whole path, as the path tracer's
//! does (0: emitters seen directly, 1: direct lighting): a strategy with s light vertices and
//! t camera vertices is used when s + t - 2 <= max_depth. `[render] spp` camera samples per
//! pixel, each with one light path.
//!
//! Veach's bidirectional path tracer (Veach 1997, chapter 10): for every camera sample, a
//! camera subpath x0 (the pinhole) x1 ... and a light subpath y0 (on a light chosen in
//! proportion to power) y1 ... are traced by sampling BSDFs (Russian roulette past `rr_depth`),
//! then every pair of their vertices is connected by a shadow ray. Strategy (s, t) uses the
//! first s light and t camera vertices:
//!
//! * s = 0: the camera subpath reaches an emitter (an area light, or the environment);
//! * s = 1: next-event estimation from a camera vertex (a fresh light sample, as `path`'s);
//! * t = 1: a light vertex is connected to the pinhole, and what it sends there is added to
//!   the pixel it lands on (a splat: `foton_core::render::render_pixels_splatting`), light
//!   tracing; s = 1, t = 1 is an area light's point seen directly;
//! * s, t >= 2: a light vertex and a camera vertex connected.
//!
//! The strategies are combined by the power heuristic, their weights computed in O(1) per
//! connection from two running quantities per vertex (SmallVCM's `dVCM` and `dVC`, module
//! [`mis`]). Vertices on delta surfaces (mirror, smooth glass; the smooth coat of a plastic when
//! it was the part sampled) are passed through by sampling and never connected. Point, spot
//! and directional lights are never hit: their paths are found by the strategies with s >= 1.
//! A point or spot light is not seen by the camera (s = 1, t = 1 is left out for them, as the
//! path tracer never sees them).
//!
//! What it is good at: light that reaches the visible surfaces only through other diffuse or
//! glossy ones, and small lights inside fixtures (Veach's `veach-bidir`), where a path tracer's
//! shadow rays are blocked and its rare lucky paths are fireflies. What it is not: caustics seen
//! through glass (S D S paths: every connection meets a delta vertex), which photon mapping
//! renders.
//!
//! Not supported, refused with an error: participating media (`path` and `vpm` render them)
//! and `hide_emitters` (light paths connected to the camera would be blocked by emitters that
//! camera rays pass through).
//!
//! The subpaths and their MIS quantities are written to serve `vcm` too: with merging switched
//! off its weights are these.

pub mod mis;

use foton_core::bsdf::Bsdf;
use foton_core::error::Error;
use foton_core::geometry::{Hit, Ray, offset_origin};
use foton_core::integrator::{Integrator, Parameter, RenderContext};
use foton_core::light::Light;
use foton_core::material::TransportMode;
use foton_core::props::Properties;
use foton_core::render::{PixelSample, Splats, render_pixels_splatting};
use foton_core::sampling::Sampler;
use foton_core::scene::Scene;
use foton_core::walk::{RayWalk, Reached};
use foton_core::{Result, Rgb, Vec3, film::Film};
use mis::{Running, mis, weight_connect, weight_direct, weight_emitter_hit, weight_to_camera};

pub struct Bdpt {
    max_depth: u32,
    rr_depth: u32,
    strategy: Strategy,
    light_image: bool,
}

/// Which strategies a render uses (the `strategy` parameter).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Strategy {
    /// Every strategy, weighted by MIS (`"all"`).
    All,
    /// Only the strategy with s light and t camera vertices, unweighted (`"s,t"`).
    Only(u32, u32),
    /// Only the strategies with t = 1, unweighted: a light tracer (`"light"`).
    Light,
}

impl Strategy {
    /// Reads `"all"`, `"light"` or `"s,t"` (s >= 0, t >= 1, s + t >= 2).
    pub fn parse(text: &str) -> std::result::Result<Strategy, String> {
        match text.trim() {
            "all" => return Ok(Strategy::All),
            "light" => return Ok(Strategy::Light),
            _ => {}
        }
        let bad = || {
            format!(
                "expected \"all\", \"light\" or \"s,t\" (s >= 0 light vertices, t >= 1 camera \
                 vertices, s + t >= 2), found \"{text}\""
            )
        };
        let (s, t) = text.split_once(',').ok_or_else(bad)?;
        let s: u32 = s.trim().parse().map_err(|_| bad())?;
        let t: u32 = t.trim().parse().map_err(|_| bad())?;
        if t == 0 || s + t < 2 {
            return Err(bad());
        }
        Ok(Strategy::Only(s, t))
    }

    /// The value as a scene file writes it.
    pub fn name(self) -> String {
        match self {
            Strategy::All => "all".into(),
            Strategy::Light => "light".into(),
            Strategy::Only(s, t) => format!("{s},{t}"),
        }
    }
}

/// A vertex of a subpath where it can be connected (its BSDF is not a delta).
#[derive(Clone, Copy, Debug)]
pub struct Vertex {
    pub p: Vec3,
    /// Geometric normal (the primitive's orientation).
    pub ng: Vec3,
    /// Unit direction back along the subpath (towards the camera, or where the light came from).
    pub wo: Vec3,
    pub bsdf: Bsdf,
    /// Throughput of the subpath up to this vertex (its own BSDF not included): radiance
    /// weights from the camera, flux over pdfs from the light.
    pub beta: Rgb,
    pub running: Running,
    /// Segments from the subpath's first vertex (the pinhole or the light).
    pub length: u32,
}

/// A light subpath's first vertex on an area light, for s = 1, t = 1.
#[derive(Clone, Copy, Debug)]
struct Origin {
    light: usize,
    p: Vec3,
    n: Vec3,
    /// pick x pdf_pos: its density per unit area.
    pdf: f32,
}

impl Bdpt {
    pub fn new(max_depth: u32, rr_depth: u32, strategy: Strategy, light_image: bool) -> Self {
        Bdpt {
            max_depth,
            rr_depth,
            strategy,
            light_image,
        }
    }

    /// The weight of strategy (s, t): 0 if it is not rendered (beyond `max_depth`, or another
    /// strategy was asked for), 1 when it is rendered alone, else `mis_weight()`.
    #[inline]
    fn weight(&self, s: u32, t: u32, mis_weight: impl FnOnce() -> f32) -> f32 {
        if s + t > self.max_depth.saturating_add(2) || (t == 1 && !self.light_image) {
            return 0.0;
        }
        match self.strategy {
            Strategy::All => mis_weight(),
            Strategy::Only(s0, t0) => ((s, t) == (s0, t0)) as u8 as f32,
            Strategy::Light => (t == 1) as u8 as f32,
        }
    }

    /// One camera sample: its own estimate (strategies t >= 2); what its light path brings to
    /// the camera (t = 1) goes to `splats`.
    pub fn sample(
        &self,
        scene: &Scene,
        ps: &PixelSample,
        sampler: &mut Sampler,
        splats: &mut Splats<'_>,
        rays: &mut u64,
    ) -> Rgb {
        let cap = (self.max_depth as usize + 2).min(32);
        let mut camera = Vec::with_capacity(cap);
        let mut radiance = self.camera_subpath(scene, ps, sampler, &mut camera, rays);
        let mut light = Vec::with_capacity(cap);
        let origin = self.light_subpath(scene, sampler, &mut light, rays);

        // ---- t = 1: light vertices connected to the pinhole, splatted ----
        if let Some(o) = origin {
            self.splat_origin(scene, &o, splats, rays);
        }
        for v in &light {
            self.splat_vertex(scene, v, splats, rays);
        }

        // ---- s >= 1, t >= 2: connections from each camera vertex ----
        for c in &camera {
            radiance += self.direct(scene, c, sampler, rays);
            for v in &light {
                radiance += self.connect(scene, c, v, rays);
            }
        }
        radiance
    }

    /// Traces the camera subpath from `ps`, keeping its connectable vertices in `vertices`, and
    /// returns the emission it meets (s = 0).
    fn camera_subpath(
        &self,
        scene: &Scene,
        ps: &PixelSample,
        sampler: &mut Sampler,
        vertices: &mut Vec<Vertex>,
        rays: &mut u64,
    ) -> Rgb {
        let (_, pdf_we) = scene.camera.pdf_we(ps.ray.dir);
        let pdf_camera = ps.filter_pdf * pdf_we;
        if pdf_camera <= 0.0 {
            return Rgb::ZERO;
        }
        let mut running = Running::camera(pdf_camera);
        if !self.light_image {
            // d_vcm starts as the t = 1 strategy's share: without it, no weight counts it.
            running.d_vcm = 0.0;
        }
        let mut radiance = Rgb::ZERO;
        let mut beta = Rgb::ONE;
        let mut walk = RayWalk::camera(scene, ps.ray);
        let mut prev = ps.ray.origin;
        let mut length = 0u32;
        loop {
            let seg = walk.segment(scene, rays);
            let Some(hit) = seg.hit else {
                // ---- s = 0: the environment ----
                length += 1;
                if let Some((id, le)) = scene.escaped(seg.ray.dir) {
                    let dir = seg.ray.dir;
                    let w = self.weight(0, length + 1, || {
                        if length == 1 {
                            // No other strategy sees a light at infinity directly.
                            return 1.0;
                        }
                        let light = &scene.lights[id as usize];
                        let pick = scene.light_pmf(id as usize);
                        let direct = pick * light.pdf_li(prev, prev + dir, Vec3::ZERO);
                        let (pos, pdf_dir) = light.pdf_le(Vec3::ZERO, -dir);
                        weight_emitter_hit(&running, direct, pick * pos * pdf_dir)
                    });
                    radiance += beta * le * w;
                }
                break;
            };
            let bsdf = match walk.reach(scene, &hit) {
                Reached::Surface(bsdf) => bsdf,
                Reached::Crossed => continue,
                Reached::Ended => break,
            };
            length += 1;
            let wo = -seg.ray.dir;
            let dist2 = prev.distance_squared(hit.p);
            running.arrive(Some(dist2), hit.ng.dot(wo));

            // ---- s = 0: an area light reached ----
            if let Some((id, light)) = scene.area_light(&hit) {
                let le = light.emitted(hit.ng, wo);
                if le != Rgb::ZERO {
                    let w = self.weight(0, length + 1, || {
                        let pick = scene.light_pmf(id as usize);
                        let (pos, pdf_dir) = light.pdf_le(hit.ng, wo);
                        // The point sampled by the other strategy that ends here: next-event
                        // estimation from the previous vertex, or, seen from the camera, the
                        // light's emission connected to the camera (s = 1, t = 1).
                        let direct = if length == 1 {
                            pick * pos
                        } else {
                            pick * light.pdf_li(prev, hit.p, hit.ng) * hit.ng.dot(wo).abs() / dist2
                        };
                        weight_emitter_hit(&running, direct, pick * pos * pdf_dir)
                    });
                    radiance += beta * le * w;
                }
            }
            if length > self.max_depth {
                break;
            }
            if !bsdf.is_delta() {
                vertices.push(Vertex {
                    p: hit.p,
                    ng: hit.ng,
                    wo,
                    bsdf,
                    beta,
                    running,
                    length,
                });
            }
            // ---- BSDF sampling ----
            let (u, uc) = (sampler.next_2d(), sampler.next_f32());
            let Some(bs) = bsdf.sample(wo, u, uc, TransportMode::Radiance) else {
                break;
            };
            scatter(&mut running, &bsdf, &hit, wo, bs.wi, bs.pdf, bs.delta);
            beta *= bs.weight;
            if beta == Rgb::ZERO || !self.russian_roulette(length, &mut beta, sampler) {
                break;
            }
            prev = hit.p;
            walk.scatter_at_surface(scene, &hit, bs.wi);
        }
        radiance
    }

    /// Traces a light subpath from a light chosen in proportion to power, keeping its
    /// connectable vertices in `vertices`; returns its origin if it lies on an area light.
    fn light_subpath(
        &self,
        scene: &Scene,
        sampler: &mut Sampler,
        vertices: &mut Vec<Vertex>,
        rays: &mut u64,
    ) -> Option<Origin> {
        let u_light = sampler.next_f32();
        let (u_pos, u_dir, u_shape) = (sampler.next_2d(), sampler.next_2d(), sampler.next_f32());
        let (id, pick) = scene.sample_light(u_light)?;
        let light = &scene.lights[id];
        let e = light.sample_emission(u_pos, u_dir, u_shape);
        let origin = matches!(light, Light::Area { .. }).then_some(Origin {
            light: id,
            p: e.origin,
            n: e.n,
            pdf: pick * e.pdf_pos,
        });
        let emission_pdf = pick * e.pdf_pos * e.pdf_dir;
        if emission_pdf.is_nan() || emission_pdf <= 0.0 || e.le == Rgb::ZERO {
            return origin;
        }
        let infinite = light.is_infinite();
        let cos_light = if e.n == Vec3::ZERO {
            1.0
        } else {
            e.n.dot(e.dir).abs()
        };
        let mut running = Running::light(emission_pdf, cos_light, light.is_delta());
        let mut beta = e.le * (cos_light / emission_pdf);
        let mut walk = RayWalk::new(Ray::new(offset_origin(e.origin, e.n, e.dir), e.dir), None);
        let mut prev = e.origin;
        let mut length = 0u32;
        loop {
            let seg = walk.segment(scene, rays);
            let Some(hit) = seg.hit else {
                break;
            };
            let bsdf = match walk.reach(scene, &hit) {
                Reached::Surface(bsdf) => bsdf,
                Reached::Crossed => continue,
                Reached::Ended => break,
            };
            length += 1;
            let wo = -seg.ray.dir;
            let dist2 = prev.distance_squared(hit.p);
            if length == 1 {
                // Next-event estimation's density of the origin, seen from here.
                let direct = pick
                    * match light {
                        Light::Area { .. } => {
                            light.pdf_li(hit.p, e.origin, e.n) * cos_light / dist2
                        }
                        _ if light.is_delta() => 1.0,
                        _ => light.pdf_li(hit.p, hit.p - e.dir, Vec3::ZERO),
                    };
                running.first_hit(direct, emission_pdf);
            }
            running.arrive((length > 1 || !infinite).then_some(dist2), hit.ng.dot(wo));
            if !bsdf.is_delta() {
                vertices.push(Vertex {
                    p: hit.p,
                    ng: hit.ng,
                    wo,
                    bsdf,
                    beta,
                    running,
                    length,
                });
            }
            if length >= self.max_depth {
                break;
            }
            let (u, uc) = (sampler.next_2d(), sampler.next_f32());
            let Some(bs) = bsdf.sample(wo, u, uc, TransportMode::Importance) else {
                break;
            };
            scatter(&mut running, &bsdf, &hit, wo, bs.wi, bs.pdf, bs.delta);
            beta *= bs.weight;
            if beta == Rgb::ZERO || !self.russian_roulette(length, &mut beta, sampler) {
                break;
            }
            prev = hit.p;
            walk.scatter_at_surface(scene, &hit, bs.wi);
        }
        origin
    }

    /// t = 1 for a light vertex: connected to the pinhole and splatted on the pixels whose
    /// filter covers where it lands.
    fn splat_vertex(&self, scene: &Scene, v: &Vertex, splats: &mut Splats<'_>, rays: &mut u64) {
        let s = v.length + 1;
        if self.weight(s, 1, || 1.0) == 0.0 {
            return;
        }
        let camera = &scene.camera;
        let Some(cs) = camera.sample_wi(v.p) else {
            return;
        };
        let f = light_vertex_f(v, cs.wi);
        if f == Rgb::ZERO {
            return;
        }
        *rays += 1;
        if scene.occluded(v.p, v.ng, camera.position, Vec3::ZERO) {
            return;
        }
        let base = v.beta * f * (cs.we / cs.pdf);
        // The camera's density of having sampled v, per unit area there (filter aside).
        let pdf_camera = camera.pdf_we(-cs.wi).1 * v.ng.dot(cs.wi).abs() / (cs.dist * cs.dist);
        let pdf_rev = v.bsdf.pdf(cs.wi, v.wo);
        let (width, height) = (scene.film.width, scene.film.height);
        scene
            .film
            .filter
            .footprint(cs.film, width, height, |x, y, h| {
                let w = self.weight(s, 1, || {
                    weight_to_camera(&v.running, h * pdf_camera, pdf_rev)
                });
                splats.add(x, y, base * (h * w));
            });
    }

    /// s = 1, t = 1: a point of an area light connected to the pinhole (the light seen
    /// directly, as light tracing finds it).
    fn splat_origin(&self, scene: &Scene, o: &Origin, splats: &mut Splats<'_>, rays: &mut u64) {
        if self.weight(1, 1, || 1.0) == 0.0 {
            return;
        }
        let camera = &scene.camera;
        let Some(cs) = camera.sample_wi(o.p) else {
            return;
        };
        let le = scene.lights[o.light].emitted(o.n, cs.wi);
        if le == Rgb::ZERO {
            return;
        }
        *rays += 1;
        if scene.occluded(o.p, o.n, camera.position, Vec3::ZERO) {
            return;
        }
        let cos = o.n.dot(cs.wi).abs();
        let base = le * (cos / o.pdf * cs.we / cs.pdf);
        let pdf_camera = camera.pdf_we(-cs.wi).1 * cos / (cs.dist * cs.dist);
        // The only other strategy is the camera ray that reaches the point (s = 0, t = 2).
        let running = Running {
            d_vcm: mis(1.0 / o.pdf),
            d_vc: 0.0,
        };
        let (width, height) = (scene.film.width, scene.film.height);
        scene
            .film
            .filter
            .footprint(cs.film, width, height, |x, y, h| {
                let w = self.weight(1, 1, || weight_to_camera(&running, h * pdf_camera, 0.0));
                splats.add(x, y, base * (h * w));
            });
    }

    /// s = 1: next-event estimation from camera vertex `c`.
    fn direct(&self, scene: &Scene, c: &Vertex, sampler: &mut Sampler, rays: &mut u64) -> Rgb {
        let u_light = sampler.next_f32();
        let (u, uc) = (sampler.next_2d(), sampler.next_f32());
        let t = c.length + 1;
        if self.weight(1, t, || 1.0) == 0.0 {
            return Rgb::ZERO;
        }
        let Some((id, pick)) = scene.sample_light(u_light) else {
            return Rgb::ZERO;
        };
        let light = &scene.lights[id];
        let Some(ls) = light.sample_li(c.p, u, uc) else {
            return Rgb::ZERO;
        };
        if ls.li == Rgb::ZERO || ls.pdf.is_nan() || ls.pdf <= 0.0 {
            return Rgb::ZERO;
        }
        let (f, scatter_pdf) = c.bsdf.eval_pdf(c.wo, ls.wi);
        if f == Rgb::ZERO {
            return Rgb::ZERO;
        }
        *rays += 1;
        if scene.occluded(c.p, c.ng, ls.p, ls.n) {
            return Rgb::ZERO;
        }
        let direct_pdf = pick * ls.pdf;
        let w = self.weight(1, t, || {
            let (pos, pdf_dir) = light.pdf_le(ls.n, -ls.wi);
            let emission_pdf = pick * pos * pdf_dir;
            let cos_x = c.ng.dot(ls.wi).abs();
            // Emission's density of reaching c per unit area there, over next-event
            // estimation's of the light point per unit area on it (per solid angle for lights
            // at infinity; a point light's position is a discrete choice).
            let emission_ratio = match light {
                Light::Area { .. } => emission_pdf * cos_x / (direct_pdf * ls.n.dot(ls.wi).abs()),
                Light::Point { .. } | Light::Spot { .. } => {
                    emission_pdf * cos_x / (pick * ls.dist * ls.dist)
                }
                _ => emission_pdf * cos_x / direct_pdf,
            };
            let hit_pdf = if ls.delta { 0.0 } else { scatter_pdf };
            weight_direct(
                &c.running,
                hit_pdf,
                direct_pdf,
                emission_ratio,
                c.bsdf.pdf(ls.wi, c.wo),
            )
        });
        c.beta * f * ls.li * (w / direct_pdf)
    }

    /// s, t >= 2: camera vertex `c` connected with light vertex `v`.
    fn connect(&self, scene: &Scene, c: &Vertex, v: &Vertex, rays: &mut u64) -> Rgb {
        let (s, t) = (v.length + 1, c.length + 1);
        if self.weight(s, t, || 1.0) == 0.0 {
            return Rgb::ZERO;
        }
        let d = v.p - c.p;
        let dist2 = d.length_squared();
        if dist2.is_nan() || dist2 <= 0.0 {
            return Rgb::ZERO;
        }
        let dir = d / dist2.sqrt();
        let f_c = c.bsdf.eval(c.wo, dir);
        if f_c == Rgb::ZERO {
            return Rgb::ZERO;
        }
        let f_v = light_vertex_f(v, -dir);
        if f_v == Rgb::ZERO {
            return Rgb::ZERO;
        }
        *rays += 1;
        if scene.occluded(c.p, c.ng, v.p, v.ng) {
            return Rgb::ZERO;
        }
        let w = self.weight(s, t, || {
            let (cos_c, cos_v) = (c.ng.dot(dir).abs(), v.ng.dot(dir).abs());
            weight_connect(
                &c.running,
                &v.running,
                c.bsdf.pdf(c.wo, dir) * cos_v / dist2,
                c.bsdf.pdf(dir, c.wo),
                v.bsdf.pdf(v.wo, -dir) * cos_c / dist2,
                v.bsdf.pdf(-dir, v.wo),
            )
        });
        c.beta * f_c * f_v * v.beta * (w / dist2)
    }

    /// Russian roulette past `rr_depth` scattering events, as the path tracer's: keeps the
    /// throughput's expectation. False if the subpath ends.
    fn russian_roulette(&self, depth: u32, beta: &mut Rgb, sampler: &mut Sampler) -> bool {
        if depth < self.rr_depth {
            return true;
        }
        let survive = beta.max_element().min(0.95);
        if survive <= 0.0 || sampler.next_f32() >= survive {
            return false;
        }
        *beta /= survive;
        true
    }
}

/// What light vertex `v` sends along `w` (unit, away from it), per unit of its throughput:
/// f(w, wo) |w.ng| with the shading-normal correction of importance transport (Veach 1997,
/// section 5.3): f |wo.ns| |w.ng| / |wo.ng|, what `Bsdf::eval` (which carries |wo.ns|) times
/// |w.ng| / |wo.ng| gives.
#[inline]
fn light_vertex_f(v: &Vertex, w: Vec3) -> Rgb {
    let cos_wo = v.ng.dot(v.wo).abs();
    if cos_wo == 0.0 {
        return Rgb::ZERO;
    }
    v.bsdf.eval(w, v.wo) * (v.ng.dot(w).abs() / cos_wo)
}

/// The MIS update of a subpath that scatters at `hit` from `wo` to `wi` (sampled with density
/// `pdf`, a delta or not).
#[inline]
fn scatter(
    running: &mut Running,
    bsdf: &Bsdf,
    hit: &Hit,
    wo: Vec3,
    wi: Vec3,
    pdf: f32,
    delta: bool,
) {
    let cos_out = hit.ng.dot(wi);
    if delta {
        running.scatter(cos_out, pdf, pdf, true);
    } else {
        running.scatter(cos_out, bsdf.pdf(wo, wi), bsdf.pdf(wi, wo), false);
    }
}

impl Integrator for Bdpt {
    fn render(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Film> {
        render_pixels_splatting(scene, ctx, |ps, sampler, splats, rays| {
            self.sample(scene, ps, sampler, splats, rays)
        })
    }

    fn name(&self) -> &str {
        "bdpt"
    }

    fn parameters(&self) -> Vec<Parameter> {
        vec![
            Parameter::int("rr_depth", self.rr_depth),
            Parameter::bool("light_image", self.light_image),
            Parameter::str("strategy", self.strategy.name()),
        ]
    }
}

/// Reads the parameters (see the table above).
pub fn create(props: &Properties<'_>, scene: &Scene) -> Result<Box<dyn Integrator>> {
    let rr_depth = props.u32("rr_depth", 5)?;
    let light_image = props.bool("light_image", true)?;
    let strategy = Strategy::parse(props.string("strategy", "all")?)
        .map_err(|e| props.error("strategy", e))?;
    if scene.has_media() {
        return Err(Error::Usage(format!(
            "{}: the scene has participating media, which `bdpt` does not render yet (use `path` or `vpm`)",
            scene.file.display()
        )));
    }
    if scene.render.hide_emitters {
        return Err(Error::Usage(format!(
            "{}: `bdpt` does not render with hide_emitters (light paths connected to the camera \
             would be blocked by the emitters camera rays pass through): use `path`",
            scene.file.display()
        )));
    }
    Ok(Box::new(Bdpt::new(
        scene.render.max_depth,
        rr_depth,
        strategy,
        light_image,
    )))
}

foton_core::declare_integrator!("bdpt", "bidirectional path tracer (Veach, MIS)", create);
