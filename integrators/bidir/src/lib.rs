//! # foton-bidir: the bidirectional machinery `bdpt` and `vcm` share
//!
//! A library crate, not a plugin (a plugin crate cannot link another: each cdylib exports the
//! plugin declaration), as `foton-photonmap` is for the photon mappers. It holds:
//!
//! * the subpath vertex ([`Vertex`]) and the random walk of both subpaths (camera and light)
//!   with the running MIS quantities of Georgiev et al.'s implementation notes (module
//!   [`mis`](mod@mis): `d_vcm`, `d_vc`, `d_vm`);
//! * the connection strategies of Veach's bidirectional path tracer: s = 0 (the camera subpath
//!   reaches an emitter), s = 1 (next-event estimation), t = 1 (a light vertex connected to the
//!   pinhole and splatted), s, t >= 2 (a light vertex connected with a camera vertex), each
//!   weighted in O(1) by the power heuristic;
//! * the weight of a merge (vertex merging, `vcm`), [`mis::weight_merge`].
//!
//! [`Bidir`] is the estimator's configuration: `bdpt` uses it with merging off
//! ([`mis::Factors::CONNECT`]: the weights are Veach's), `vcm` with the factors of each
//! iteration's merge radius ([`mis::Factors::vcm`]). With merging off every operation is the
//! one `bdpt` did before the crate existed (adding a zero factor changes no bit), so `bdpt`'s
//! images are bit-identical.
//!
//! Vertices on delta surfaces (mirror, smooth glass; the smooth coat of a plastic when it was
//! the part sampled) are passed through by sampling and never connected or merged. Point, spot
//! and directional lights are never hit: their paths are found by the strategies with s >= 1.
//! Participating media along both subpaths (as Mitsuba 0.6's `bdpt`): see `bdpt`'s crate doc.

mod connect;
pub mod mis;
mod vertex;

pub use vertex::{At, Vertex};

use foton_core::api::{
    Light, LightType, PixelSample, Ray, RayWalk, Reached, Rgb, Sampler, Scene, Splats,
    TransportMode, Vec2, Vec3, channel, offset_origin, russian_roulette,
};
use mis::{Factors, Running, weight_emitter_hit};

/// The bidirectional estimator: which strategies it uses and how they are weighted.
#[derive(Clone, Copy, Debug)]
pub struct Bidir {
    pub max_depth: u32,
    pub rr_depth: u32,
    pub strategy: Strategy,
    pub light_image: bool,
    /// The merging terms of the MIS weights (zero without merging).
    pub factors: Factors,
    /// Connections (s >= 1) are used; false in `vcm`'s `ppm` mode.
    pub connect: bool,
    /// Camera subpaths stop at their first connectable vertex, and emitters count only when
    /// reached through delta vertices alone (`vcm`'s `ppm` mode, SmallVCM's `kPpm`).
    pub first_vertex_only: bool,
}

/// Where the contributions of light paths connected to the camera (t = 1) go: the splatting
/// film of core's pixel loop ([`Splats`]) or an integrator's own buffer. With `foton render
/// --techniques`, also where each strategy's share goes ([`SplatSink::add_strategy`],
/// [`SplatSink::share`]); the defaults keep none (nothing is done for them in a plain render).
pub trait SplatSink {
    /// Whether the sink keeps the strategies' shares ([`SplatSink::share`]); false: the camera
    /// subpath is traced without reporting them.
    const SHARES: bool = false;

    /// Adds `value` times `weight` to pixel (x, y): `value` must be usable (finite, not
    /// negative; [`Splats::add_weighted`]), `weight` is the filter's weight of the pixel at the
    /// splat's film point (negative in a negative lobe, exactly 1.0 for a positive filter).
    fn add(&mut self, x: u32, y: u32, value: Rgb, weight: f32);

    /// Adds `value` times `weight`, the (MIS-weighted) contribution of strategy (s, t = 1), to
    /// pixel (x, y), as [`SplatSink::add`].
    #[inline(always)]
    fn add_strategy(&mut self, _s: u32, x: u32, y: u32, value: Rgb, weight: f32) {
        self.add(x, y, value, weight)
    }

    /// Strategy (s, t)'s (t >= 2) MIS-weighted share of the camera sample's own estimate,
    /// which [`Bidir::sample`] also adds to what it returns.
    #[inline(always)]
    fn share(&mut self, _s: u32, _t: u32, _value: Rgb) {}
}

impl SplatSink for Splats<'_> {
    #[inline]
    fn add(&mut self, x: u32, y: u32, value: Rgb, weight: f32) {
        Splats::add_weighted(self, x, y, value, weight)
    }
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

/// A light subpath's first vertex on an area light, for s = 1, t = 1.
#[derive(Clone, Copy, Debug)]
pub struct Origin {
    light: usize,
    p: Vec3,
    n: Vec3,
    uv: Vec2,
    /// pick x pdf_pos: its density per unit area.
    pdf: f32,
    medium: Option<u32>,
}

/// Which end a subpath starts from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    Camera,
    Light,
}

/// What a light subpath needs at its first vertex: next-event estimation's density of its
/// origin, seen from there.
#[derive(Clone, Copy, Debug)]
struct Emitted<'a> {
    light: &'a Light,
    pick: f32,
    origin: Vec3,
    n: Vec3,
    dir: Vec3,
    cos_light: f32,
    emission_pdf: f32,
}

impl Bidir {
    /// Veach's bidirectional path tracer (`bdpt`): connections only, merging off.
    pub fn new(max_depth: u32, rr_depth: u32, strategy: Strategy, light_image: bool) -> Self {
        Bidir {
            max_depth,
            rr_depth,
            strategy,
            light_image,
            factors: Factors::CONNECT,
            connect: true,
            first_vertex_only: false,
        }
    }

    /// The weight of strategy (s, t): 0 if it is not rendered (beyond `max_depth`, or another
    /// strategy was asked for), 1 when it is rendered alone, else `mis_weight()`.
    #[inline]
    fn weight(&self, s: u32, t: u32, mis_weight: impl FnOnce() -> f32) -> f32 {
        if s + t > self.max_depth.saturating_add(2)
            || (t == 1 && !self.light_image)
            || (s >= 1 && !self.connect)
        {
            return 0.0;
        }
        match self.strategy {
            Strategy::All => mis_weight(),
            Strategy::Only(s0, t0) => ((s, t) == (s0, t0)) as u8 as f32,
            Strategy::Light => (t == 1) as u8 as f32,
        }
    }

    /// The weight of a camera subpath of t vertices reaching an emitter (s = 0); `specular`:
    /// every scattering before was a delta sample. Without connections (`ppm` mode) only
    /// such paths count, unweighted: the others are found by merging (SmallVCM's `kPpm`).
    #[inline]
    fn weight_emitter(&self, t: u32, specular: bool, mis_weight: impl FnOnce() -> f32) -> f32 {
        if !self.connect {
            let counted = specular && t <= self.max_depth.saturating_add(2);
            return counted as u8 as f32;
        }
        self.weight(0, t, mis_weight)
    }

    /// One camera sample: its own estimate (strategies t >= 2); what its light path brings to
    /// the camera (t = 1) goes to `splats`. `light_media` is the medium each light emits into.
    pub fn sample<S: SplatSink>(
        &self,
        scene: &Scene,
        light_media: &[Option<u32>],
        ps: &PixelSample,
        sampler: &mut Sampler,
        splats: &mut S,
        rays: &mut u64,
    ) -> Rgb {
        let cap = (self.max_depth as usize + 2).min(32);
        let mut camera = Vec::with_capacity(cap);
        let mut radiance = if S::SHARES {
            self.camera_subpath_with(scene, ps, sampler, &mut camera, rays, |t, value| {
                splats.share(0, t, value)
            })
        } else {
            self.camera_subpath(scene, ps, sampler, &mut camera, rays)
        };
        let mut light = Vec::with_capacity(cap);
        let origin = self.light_subpath(scene, light_media, sampler, &mut light, rays);

        // ---- t = 1: light vertices connected to the pinhole, splatted ----
        if let Some(o) = origin {
            self.splat_origin(scene, &o, sampler, splats, rays);
        }
        for v in &light {
            self.splat_vertex(scene, v, sampler, splats, rays);
        }

        // ---- s >= 1, t >= 2: connections from each camera vertex ----
        for c in &camera {
            let direct = self.direct(scene, c, sampler, rays);
            splats.share(1, c.length + 1, direct);
            radiance += direct;
            for v in &light {
                let connected = self.connect(scene, c, v, rays);
                splats.share(v.length + 1, c.length + 1, connected);
                radiance += connected;
            }
        }
        radiance
    }

    /// Traces the camera subpath from `ps`, keeping its connectable vertices in `vertices`, and
    /// returns the emission it meets (s = 0).
    pub fn camera_subpath(
        &self,
        scene: &Scene,
        ps: &PixelSample,
        sampler: &mut Sampler,
        vertices: &mut Vec<Vertex>,
        rays: &mut u64,
    ) -> Rgb {
        self.camera_walk(scene, ps, sampler, vertices, rays, None)
    }

    /// [`Bidir::camera_subpath`] that also hands `emitted` each emitter's weighted
    /// contribution as it is met, with its strategy's t (s = 0).
    pub fn camera_subpath_with(
        &self,
        scene: &Scene,
        ps: &PixelSample,
        sampler: &mut Sampler,
        vertices: &mut Vec<Vertex>,
        rays: &mut u64,
        mut emitted: impl FnMut(u32, Rgb),
    ) -> Rgb {
        self.camera_walk(scene, ps, sampler, vertices, rays, Some(&mut emitted))
    }

    /// The camera subpath of [`Bidir::camera_subpath`], its emitter hits also handed to
    /// `emitted` if there is one (once per hit: no cost per vertex without it).
    fn camera_walk(
        &self,
        scene: &Scene,
        ps: &PixelSample,
        sampler: &mut Sampler,
        vertices: &mut Vec<Vertex>,
        rays: &mut u64,
        emitted: Option<&mut dyn FnMut(u32, Rgb)>,
    ) -> Rgb {
        let margin = scene.film().filter.margin();
        let pdf_camera = ps.filter_pdf * scene.camera().pdf_ray(&ps.ray, margin);
        if pdf_camera <= 0.0 {
            return Rgb::ZERO;
        }
        let mut running = Running::camera(pdf_camera);
        if !self.light_image {
            // d_vcm starts as the t = 1 strategy's share: without it, no weight counts it.
            running.d_vcm = 0.0;
        }
        let walk = RayWalk::camera(scene, ps.ray);
        self.random_walk(
            scene,
            Side::Camera,
            walk,
            Rgb::ONE,
            running,
            None,
            sampler,
            vertices,
            rays,
            emitted,
        )
    }

    /// Traces a light subpath from a light chosen in proportion to power, keeping its
    /// connectable vertices in `vertices`; returns its origin if it lies on an area light.
    pub fn light_subpath(
        &self,
        scene: &Scene,
        light_media: &[Option<u32>],
        sampler: &mut Sampler,
        vertices: &mut Vec<Vertex>,
        rays: &mut u64,
    ) -> Option<Origin> {
        let u_light = sampler.next_f32();
        let (u_pos, u_dir, u_shape) = (sampler.next_2d(), sampler.next_2d(), sampler.next_f32());
        let (id, pick) = scene.sample_light(u_light)?;
        let light = &scene.lights()[id];
        let e = light.sample_emission(u_pos, u_dir, u_shape);
        let medium = light_media.get(id).copied().flatten();
        let origin = (light.light_type() == LightType::Area).then_some(Origin {
            light: id,
            p: e.origin,
            n: e.n,
            uv: e.uv,
            pdf: pick * e.pdf_pos,
            medium,
        });
        let emission_pdf = pick * e.pdf_pos * e.pdf_dir;
        if emission_pdf.is_nan() || emission_pdf <= 0.0 || e.le == Rgb::ZERO {
            return origin;
        }
        let cos_light = if e.n == Vec3::ZERO {
            1.0
        } else {
            e.n.dot(e.dir).abs()
        };
        let running = Running::light(emission_pdf, cos_light, light.is_delta(), &self.factors);
        let beta = e.le * (cos_light / emission_pdf);
        let ray = Ray::new(offset_origin(e.origin, e.n, e.dir), e.dir);
        let emitted = Emitted {
            light,
            pick,
            origin: e.origin,
            n: e.n,
            dir: e.dir,
            cos_light,
            emission_pdf,
        };
        self.random_walk(
            scene,
            Side::Light,
            RayWalk::new(ray, medium),
            beta,
            running,
            Some(emitted),
            sampler,
            vertices,
            rays,
            None,
        );
        origin
    }

    /// The random walk of a subpath (both sides): free flights through media, null boundaries
    /// crossed, BSDFs and phase functions sampled, Russian roulette; the connectable vertices
    /// go to `vertices` with their MIS quantities. A camera subpath also gathers the emission
    /// it meets (s = 0), which it returns, each term also handed to `on_emission` with its t.
    #[allow(clippy::too_many_arguments)]
    fn random_walk(
        &self,
        scene: &Scene,
        side: Side,
        mut walk: RayWalk,
        mut beta: Rgb,
        mut running: Running,
        emitted: Option<Emitted<'_>>,
        sampler: &mut Sampler,
        vertices: &mut Vec<Vertex>,
        rays: &mut u64,
        mut on_emission: Option<&mut dyn FnMut(u32, Rgb)>,
    ) -> Rgb {
        let mode = match side {
            Side::Camera => TransportMode::Radiance,
            Side::Light => TransportMode::Importance,
        };
        // A first segment whose densities have no distance: from a light at infinity, or
        // from an orthographic camera (parallel rays).
        let infinite = match side {
            Side::Light => emitted.is_some_and(|e| e.light.is_infinite()),
            Side::Camera => scene.camera().is_orthographic(),
        };
        let mut radiance = Rgb::ZERO;
        let mut prev = emitted.map_or(walk.ray.origin, |e| e.origin);
        let mut length = 0u32;
        // Every scattering so far was a delta sample (ppm mode counts only such emitter hits).
        let mut specular = true;
        // The MIS update on reaching a vertex at `x` (cosine `cos`, 1 in a medium).
        let arrive = |running: &mut Running, length: u32, x: Vec3, prev: Vec3, cos: f32| {
            let dist2 = prev.distance_squared(x);
            if length == 1
                && let Some(e) = emitted
            {
                // Next-event estimation's density of the light's origin, seen from x.
                let direct = e.pick
                    * match e.light.light_type() {
                        LightType::Area => e.light.pdf_li(x, e.origin, e.n) * e.cos_light / dist2,
                        LightType::DeltaPosition | LightType::DeltaDirection => 1.0,
                        // Next-event estimation never reaches a beam.
                        LightType::DeltaBeam => 0.0,
                        LightType::Infinite => e.light.pdf_li(x, x - e.dir, Vec3::ZERO),
                    };
                running.first_hit(direct, e.emission_pdf);
            }
            running.arrive((length > 1 || !infinite).then_some(dist2), cos);
        };
        loop {
            let seg = walk.segment(scene, rays);

            // ---- Medium: free flight to a scattering event or to the surface ----
            if let Some(m) = seg.interacting_medium(scene) {
                // One-sample MIS over the channels of this event (FreeFlight::weight).
                let channel = channel(sampler.next_f32());
                let flight =
                    m.sample_free_flight(&seg.start(), seg.length(), channel, sampler.next_f32());
                // ---- s = 0: the medium's emission at the event ----
                // No light subpath starts in a medium and no connection ends at an emitting
                // medium point: this strategy alone renders such paths, with weight 1.
                if side == Side::Camera && flight.emitted != Rgb::ZERO {
                    let t = length + 2;
                    let value = beta * flight.emission_weight() * self.weight(0, t, || 1.0);
                    if let Some(f) = on_emission.as_mut() {
                        f(t, value);
                    }
                    radiance += value;
                }
                beta *= flight.weight();
                if beta == Rgb::ZERO {
                    break;
                }
                if flight.scattered {
                    let x = seg.at(flight.t);
                    length += 1;
                    arrive(&mut running, length, x, prev, 1.0);
                    if side == Side::Camera && length > self.max_depth {
                        break;
                    }
                    let phase = m.phase();
                    let wo = -seg.ray.dir;
                    vertices.push(Vertex {
                        p: x,
                        at: At::Medium { phase },
                        medium: walk.medium,
                        wo,
                        beta,
                        running,
                        length,
                    });
                    if side == Side::Light && length >= self.max_depth {
                        break;
                    }
                    // ---- Phase-function sampling: p / pdf = 1 ----
                    let (wi, pdf) = phase.sample(seg.ray.dir, sampler.next_2d());
                    specular = false;
                    running.scatter(1.0, pdf, pdf, false, &self.factors);
                    if !russian_roulette(length, self.rr_depth, &mut beta, sampler) {
                        break;
                    }
                    prev = x;
                    walk.scatter_in_medium(x, wi);
                    continue;
                }
            }

            let Some(hit) = seg.hit else {
                // ---- s = 0: the environment ----
                if side == Side::Camera
                    && let Some((id, le)) = scene.escaped(seg.ray.dir)
                {
                    let t = length + 2;
                    let dir = seg.ray.dir;
                    let w = self.weight_emitter(t, specular, || {
                        if length == 0 {
                            // No other strategy sees a light at infinity directly.
                            return 1.0;
                        }
                        let light = &scene.lights()[id as usize];
                        let pick = scene.light_pmf(id as usize);
                        let direct = pick * light.pdf_li(prev, prev + dir, Vec3::ZERO);
                        let (pos, pdf_dir) = light.pdf_le(Vec3::ZERO, -dir);
                        weight_emitter_hit(&running, direct, pick * pos * pdf_dir)
                    });
                    let value = beta * le * w;
                    if let Some(f) = on_emission.as_mut() {
                        f(t, value);
                    }
                    radiance += value;
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
            arrive(&mut running, length, hit.p, prev, hit.ng.dot(wo));

            // ---- s = 0: an area light reached ----
            if side == Side::Camera
                && let Some((id, light, le)) = seg.emitted(scene)
            {
                let w = self.weight_emitter(length + 1, specular, || {
                    let pick = scene.light_pmf(id as usize);
                    let (pos, pdf_dir) = light.pdf_le(hit.ng, wo);
                    // The point sampled by the other strategy that ends here: next-event
                    // estimation from the previous vertex, or, seen from the camera, the
                    // light's emission connected to the camera (s = 1, t = 1).
                    let direct = if length == 1 {
                        pick * pos
                    } else {
                        pick * light.pdf_li(prev, hit.p, hit.ng) * hit.ng.dot(wo).abs()
                            / prev.distance_squared(hit.p)
                    };
                    weight_emitter_hit(&running, direct, pick * pos * pdf_dir)
                });
                let value = beta * le * w;
                if let Some(f) = on_emission.as_mut() {
                    f(length + 1, value);
                }
                radiance += value;
            }
            if side == Side::Camera && length > self.max_depth {
                break;
            }
            if !bsdf.is_delta() {
                vertices.push(Vertex {
                    p: hit.p,
                    at: At::Surface { hit, bsdf },
                    medium: walk.medium,
                    wo,
                    beta,
                    running,
                    length,
                });
                if side == Side::Camera && self.first_vertex_only {
                    break;
                }
            }
            if side == Side::Light && length >= self.max_depth {
                break;
            }
            // ---- BSDF sampling ----
            let (u, uc) = (sampler.next_2d(), sampler.next_f32());
            let Some(bs) = bsdf.sample(wo, u, uc, mode) else {
                break;
            };
            let cos_out = hit.ng.dot(bs.wi);
            specular &= bs.delta;
            if bs.delta {
                running.scatter(cos_out, bs.pdf, bs.pdf, true, &self.factors);
            } else {
                running.scatter(
                    cos_out,
                    bsdf.pdf(wo, bs.wi),
                    bsdf.pdf(bs.wi, wo),
                    false,
                    &self.factors,
                );
            }
            beta *= bs.weight;
            if beta == Rgb::ZERO || !russian_roulette(length, self.rr_depth, &mut beta, sampler) {
                break;
            }
            prev = hit.p;
            walk.scatter_at_surface(scene, &hit, bs.wi);
        }
        radiance
    }
}
