//! # `sppm`: stochastic progressive photon mapping (Hachisuka and Jensen 2009)
//!
//! This table is the one list of the parameters (`[integrators.sppm]`); the README, the
//! scene-format page and docs/photon-mapping.md point here.
//!
//! | parameter               | type    | meaning                                                   | default |
//! |-------------------------|---------|-----------------------------------------------------------|---------|
//! | `iterations`            | integer | camera + photon passes to run, >= 1                       | 64 (unlimited with `time`) |
//! | `time`                  | float   | run until this many seconds have passed, > 0              | none    |
//! | `photons_per_iteration` | integer | photons emitted in each iteration, >= 1                   | 100000  |
//! | `initial_radius`        | float   | every pixel's starting gather radius (world units), > 0   | automatic, below |
//! | `alpha`                 | float   | fraction of new photons kept (pixel schedule) or the radius schedule's exponent (global), in (0, 1] | 0.7 |
//! | `kernel`                | string  | `box`, `cone`, `gaussian` or a kernel plugin's name       | `box`   |
//! | `cone_c`                | float   | the cone kernel's c >= 1 (read only with `kernel = "cone"`) | 1     |
//! | `direct`                | string  | `nee` (shadow rays) or `photons`                          | `nee`   |
//! | `radius_schedule`       | string  | `pixel` (each pixel's radius from its photon statistics) or `global` (from the iteration number alone, below) | `pixel` |
//! | `glossy_roughness`      | float   | glossy lobes smoother than this (microfacet alpha) are followed by the camera pass, not estimated (docs/photon-mapping.md, "Glossy surfaces") | 0.5 |
//!
//! **Global radius schedule** (`radius_schedule = "global"`, Knaus and Zwicker 2011,
//! "Progressive photon mapping: a probabilistic approach"): iteration i gathers with
//! r_i^2 = r_1^2 prod_{j=1}^{i-1} (j + alpha) / (j + 1) (r_1 the pixel's first radius, from
//! its first iteration's camera sample alone), makes its own estimate of reflected radiance
//! beta sum_p f Phi_p K(d_p, r_i), and the pixel's radiance is the mean over iterations. The
//! radius depends on the iteration's number alone, so iterations are independent: any subset
//! of them can be rendered apart and averaged (what rendering in parts needs). The pixel
//! schedule (the default) adapts each pixel's radius to its own photon density.
//!
//! `[render] max_depth` bounds the scattering events of a whole light path, camera path's
//! delta bounces and photon's surface hits together, as in the path tracer; `[render] spp` is
//! not used (each iteration takes one new jittered camera sample per pixel). With `time`,
//! `iterations` (if given) is an upper bound. A scene with participating media is refused.
//! For `foton compare --time` the work is counted in iterations (`Integrator::budget`:
//! `integrators.sppm.iterations`); `foton photons` draws one iteration's photons (the map
//! `iteration`).
//!
//! Each iteration traces a new camera path per pixel through mirrors and glass to its first
//! diffuse point, the *visible point* (core's camera walk, `foton_core::walk`, so
//! anti-aliasing comes for free), adds the emission met and, with `direct = "nee"`, direct
//! light by core's estimator (`foton_core::api::estimate_direct`, one shadow ray); then
//! traces a batch of photons (foton-photonmap's photon pass: stored at diffuse surfaces only,
//! never on mirrors or glass), gathers at each visible point the photons within the pixel's
//! radius R that lie on a disc of the same surface (below), and updates the pixel's
//! statistics:
//!
//! ```text
//! N' = N + alpha M,   R' = R sqrt((N + alpha M) / (N + M)),   tau' = (tau + Phi) R'^2 / R^2
//! ```
//!
//! where M is the number of photons gathered and Phi = beta sum_p f(x, w_p, w) Phi_p their
//! reflected flux, the BSDF evaluated per photon with its own incoming direction w_p. The
//! pixel's radiance after n iterations is Ld / n + tau / (n pi R^2) (photon flux is divided by
//! the photons of one iteration, so n is the number of iterations). R shrinks to zero while N
//! grows without bound: the estimate is consistent, converging to the image the path tracer
//! converges to.
//!
//! **The gather disc.** A photon counts if it lies within R, its stored normal agrees with the
//! visible point's (within about 25 degrees: the same side of the same surface), its path has
//! at most the scattering events the camera path leaves, and it lies no farther from the
//! tangent plane than `DISC_THICKNESS` (foton-photonmap: 1/4) of R, as in the k-nearest
//! estimates of `photon` and `vpm`: photons on a parallel surface within R are not counted.
//!
//! **Kernels.** With a kernel K other than the box, a photon at distance d counts with weight
//! w = pi R^2 K(d, R) (1 for the box inside the disc): M is the weighted count and Phi the
//! weighted flux. w averages to one over the disc, so for a locally uniform density the
//! weighted count has the box count's expectation and the same update keeps tau / (pi R^2)
//! an estimate of reflected radiance (Knaus and Zwicker 2011 show the update needs only that).
//!
//! **Automatic initial radius.** Three times the pixel's footprint at its first visible point
//! (the angle a pixel subtends at the image centre times the length of the camera path), kept
//! within [1/1000, 1/50] of the scene's bounding-box diagonal: a few pixels wide, so that early
//! iterations find photons, and small against the scene.
//!
//! **Determinism.** Photons are traced with per-photon random streams and gathered per pixel
//! from a kd-tree built in a fixed order (foton-photonmap's `PhotonMap`), so images are
//! identical for any number of threads. Memory is bounded: one iteration's photons at a time.
//!
//! The gather selects a disc (above) and evaluates the BSDF per photon; the camera walk (null boundaries
//! crossed by core's one crossing loop, a ray ended past `MAX_NULL_CROSSINGS` crossings in a
//! row) and the direct light are core's, the same code as `path`, `photon` and `vpm` use.

use foton_core::api::{
    Budget, CameraWalk, Direct, Error, Film, Integrator, Mis, NormalizedKernel, Parameter,
    PhotonMapView, Properties, RadianceSum, RenderContext, Result, Rgb, Scatter, Scene,
    VisiblePoint, estimate_direct, splitmix64, trace_to_diffuse, usable, with_pool,
};
use foton_photonmap::map::PhotonMap;
use foton_photonmap::progressive::{
    PassBudget, Passes, SPPM_FOOTPRINTS, Tally, auto_radius, gather_disc, per_pixel, pixel_angle,
    run_passes,
};
use foton_photonmap::trace::{PathClass, STREAM_GLOBAL, TraceOptions, trace_photons};
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;

pub struct Sppm {
    /// `iterations`, `time`, `photons_per_iteration`.
    pub passes: PassBudget,
    pub initial_radius: Option<f32>,
    pub alpha: f64,
    pub kernel: NormalizedKernel,
    pub direct: Direct,
    pub max_depth: u32,
    /// How camera paths treat glossy surfaces.
    pub camera: CameraWalk,
    pub schedule: RadiusSchedule,
}

/// How the gather radius shrinks from iteration to iteration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RadiusSchedule {
    /// Per pixel, from the photons it has gathered (Hachisuka and Jensen 2009).
    Pixel,
    /// The same for every pixel, from the iteration's number alone (Knaus and Zwicker 2011):
    /// iterations are independent estimates, averaged.
    Global,
}

/// Knaus and Zwicker's radius schedule, shared with `ppb` (foton-photonmap's `progressive`).
pub use foton_photonmap::progressive::global_radius2_scale;

/// A pixel's progressive statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelStats {
    /// Gather radius R (0 until the pixel's first visible point).
    pub radius: f64,
    /// Accumulated (weighted) photon count N.
    pub n: f64,
    /// Accumulated reflected flux tau.
    pub tau: DVec3,
    /// Sum over iterations of the emission and shadow-ray direct light (pixel schedule).
    pub ld: DVec3,
    /// With the global schedule: the exact sum over iterations of each iteration's own
    /// estimate (emission, direct light and reflected radiance from its photons), so that
    /// iterations rendered in parts add up to the whole render (`radius` is then the pixel's
    /// first radius r_1).
    pub sum: RadianceSum,
}

impl PixelStats {
    /// Hachisuka and Jensen's update after gathering `m` photons that reflect flux `phi`.
    pub fn update(&mut self, alpha: f64, m: f64, phi: DVec3) {
        if m <= 0.0 {
            return;
        }
        let n_new = self.n + alpha * m;
        let shrink = n_new / (self.n + m); // R'^2 / R^2
        self.tau = (self.tau + phi) * shrink;
        self.radius *= shrink.sqrt();
        self.n = n_new;
    }

    /// The pixel's radiance estimate after `iterations` iterations (pixel schedule).
    pub fn radiance(&self, iterations: u64) -> DVec3 {
        if iterations == 0 {
            return DVec3::ZERO;
        }
        let k = iterations as f64;
        let mut l = self.ld / k;
        if self.radius > 0.0 {
            l += self.tau / (k * PI * self.radius * self.radius);
        }
        l
    }
}

/// Random stream of the camera pass.
const STREAM_CAMERA: u64 = 0x7370_706d;

/// What an iteration's camera pass found at one pixel.
#[derive(Clone, Copy)]
struct CameraSample {
    /// Emission and shadow-ray direct light, weighted by the path throughput.
    ld: Rgb,
    visible: Option<VisiblePoint>,
    /// The camera sample's filter weight, which scales all it brings (its direct light and
    /// its visible point's gathers), once they are found usable: exactly 1.0 for a positive
    /// filter.
    weight: f32,
}

impl CameraSample {
    /// How far along the camera path the visible point lies (infinite without one: such a
    /// pixel gets the largest automatic radius).
    fn distance(&self) -> f32 {
        self.visible
            .as_ref()
            .map_or(f32::INFINITY, |vp| vp.distance)
    }
}

impl Sppm {
    /// The camera pass of iteration `iteration` into `samples` (one a pixel, row by row; a
    /// buffer kept across iterations, so that a pass neither allocates nor copies the
    /// samples on one thread); returns the rays it traced.
    fn camera_pass(&self, scene: &Scene, iteration: u64, samples: &mut Vec<CameraSample>) -> u64 {
        let (width, height) = (scene.film().width, scene.film().height);
        let none = CameraSample {
            ld: Rgb::ZERO,
            visible: None,
            weight: 0.0,
        };
        samples.resize(width as usize * height as usize, none);
        samples
            .par_chunks_mut(width as usize)
            .enumerate()
            .map(|(y, row)| {
                let y = y as u32;
                let mut row_rays = 0u64;
                for (x, sample) in row.iter_mut().enumerate() {
                    let x = x as u32;
                    let pixel = y as u64 * width as u64 + x as u64;
                    let mut sampler =
                        self.passes
                            .camera_sampler(scene, STREAM_CAMERA, pixel, iteration);
                    let at = scene.film().filter.sample(x, y, sampler.next_2d());
                    let ray = scene
                        .camera()
                        .generate_ray_lens(at.film, || sampler.next_2d());
                    let path =
                        trace_to_diffuse(scene, ray, self.camera, &mut sampler, &mut row_rays);
                    let mut ld = path.emitted;
                    if let (Some(vp), Direct::ShadowRays) = (&path.visible, self.direct) {
                        let at = Scatter::Surface {
                            hit: &vp.hit,
                            bsdf: &vp.bsdf,
                        };
                        ld += vp.beta
                            * estimate_direct(
                                scene,
                                at,
                                vp.wo,
                                vp.medium,
                                Mis::LightOnly,
                                &mut sampler,
                                &mut row_rays,
                            );
                    }
                    *sample = CameraSample {
                        ld,
                        visible: path.visible,
                        weight: at.weight,
                    };
                }
                row_rays
            })
            .sum()
    }

    /// The photons iteration `iteration` (0-based) stores: every one but the L D ones with
    /// shadow rays for direct light.
    fn iteration_photons(
        &self,
        scene: &Scene,
        iteration: u64,
        ctx: &RenderContext<'_>,
    ) -> Result<Vec<foton_photonmap::Photon>> {
        let options = TraceOptions {
            photons: self.passes.photons_per_iteration,
            max_depth: self.max_depth,
            seed: splitmix64(scene.render().seed ^ splitmix64(iteration)),
            stream: STREAM_GLOBAL,
            stop_at_diffuse: false,
            sobol_emission: TraceOptions::emission_for(scene.render().sampler),
        };
        let keep_direct = self.direct == Direct::Photons;
        Ok(trace_photons(scene, &options, ctx, 1, |_, class| {
            (class != PathClass::Direct || keep_direct).then_some(0)
        })?
        .pop()
        .unwrap_or_default())
    }

    /// The starting radius of a pixel whose first visible point lies `distance` along the
    /// camera path.
    fn first_radius(&self, scene: &Scene, pixel_angle: f32, distance: f32) -> f64 {
        match self.initial_radius {
            Some(r) => r as f64,
            None => auto_radius(scene, pixel_angle, distance, SPPM_FOOTPRINTS),
        }
    }
}

/// The passes of one render: each pixel's progressive statistics.
struct SppmPasses<'a> {
    sppm: &'a Sppm,
    scene: &'a Scene,
    stats: Vec<PixelStats>,
    angle: f32,
    tally: &'a Tally,
    /// Whether a pass has run (a part that starts later first needs the radii r_1).
    started: bool,
    /// The camera pass's samples, a pixel each (kept across iterations).
    camera: Vec<CameraSample>,
}

impl Passes for SppmPasses<'_> {
    fn pass(&mut self, iteration: u64, quiet: &RenderContext<'_>) -> Result<Option<String>> {
        let (sppm, scene, angle, tally) = (self.sppm, self.scene, self.angle, self.tally);
        let global = sppm.schedule == RadiusSchedule::Global;
        let mut rays = 0u64;
        if global && iteration > 0 && !self.started {
            // r_1 comes from the first iteration's camera sample: a part that starts later
            // traces that camera pass for its radii alone.
            let camera = &mut self.camera;
            rays += with_pool(quiet.threads, || sppm.camera_pass(scene, 0, camera))?;
            for (st, cs) in self.stats.iter_mut().zip(&self.camera) {
                st.radius = sppm.first_radius(scene, angle, cs.distance());
            }
        }
        self.started = true;
        let camera = &mut self.camera;
        rays += quiet.timed("camera pass", || {
            with_pool(quiet.threads, || sppm.camera_pass(scene, iteration, camera))
        })?;
        let camera = &self.camera;
        Tally::add(&tally.rays, rays);
        let photons = sppm.iteration_photons(scene, iteration, quiet)?;
        if quiet.cancelled() {
            return Ok(None);
        }
        let map = quiet.timed("photon map build", || {
            with_pool(quiet.threads, || PhotonMap::build(photons))
        })?;
        let _gather = quiet.phase("photon gather and radius update");
        let alpha = sppm.alpha;
        // r_i / r_1 of this iteration under the global schedule, the same for every pixel.
        let global_shrink = global_radius2_scale(iteration + 1, alpha).sqrt();
        with_pool(quiet.threads, || {
            self.stats
                .par_iter_mut()
                .zip(camera.par_iter())
                .for_each(|(st, cs)| {
                    let ld = if usable(cs.ld) {
                        cs.ld * cs.weight
                    } else {
                        Tally::add(&tally.bad_samples, 1);
                        Rgb::ZERO
                    };
                    if global && iteration == 0 {
                        // r_1 from the first iteration's camera sample alone (a pixel
                        // without a visible point there gets the largest automatic one),
                        // so that every iteration's radius is a function of its number.
                        st.radius = sppm.first_radius(scene, angle, cs.distance());
                    }
                    let Some(vp) = &cs.visible else {
                        match sppm.schedule {
                            RadiusSchedule::Pixel => st.ld += ld.as_dvec3(),
                            RadiusSchedule::Global => st.sum.add(ld),
                        }
                        return;
                    };
                    if st.radius == 0.0 {
                        st.radius = sppm.first_radius(scene, angle, vp.distance);
                    }
                    let r = if global {
                        (st.radius * global_shrink) as f32
                    } else {
                        st.radius as f32
                    };
                    let disc = std::f32::consts::PI * r * r;
                    // No light path longer than max_depth, as in the path tracer; a
                    // disc, as the k-nearest estimates gather from (foton-photonmap).
                    let depth = sppm.max_depth - vp.bounces;
                    let g = gather_disc(&map, vp, r, depth, &sppm.kernel);
                    Tally::add(&tally.bad_photons, g.bad);
                    let (m, phi) = (g.m, g.phi * (vp.beta * cs.weight).as_dvec3());
                    match sppm.schedule {
                        RadiusSchedule::Pixel => {
                            st.ld += ld.as_dvec3();
                            st.update(alpha, m, phi);
                        }
                        RadiusSchedule::Global => {
                            // This iteration's estimate: its direct light and reflected
                            // radiance tau / (pi r^2) with its own radius; iterations
                            // are averaged.
                            let l = ld.as_dvec3() + phi / disc as f64;
                            st.sum.add_f64(l.to_array());
                        }
                    }
                })
        })?;
        let done = iteration + 1;
        let (sum_r, lit) = self
            .stats
            .iter()
            .filter(|s| s.radius > 0.0)
            .fold((0.0, 0u64), |(s, n), st| (s + st.radius, n + 1));
        let shrink = match sppm.schedule {
            RadiusSchedule::Pixel => 1.0,
            RadiusSchedule::Global => global_radius2_scale(done, alpha).sqrt(),
        };
        Ok(Some(format!(
            "iteration {done}, {} photons, mean radius {:.4}",
            done * sppm.passes.photons_per_iteration,
            shrink * sum_r / lit.max(1) as f64
        )))
    }

    /// Under the global schedule each pixel's exact sum of per-iteration estimates, one
    /// sample per iteration; under the pixel schedule the progressive estimate as one sample.
    fn tally(&self) -> &Tally {
        self.tally
    }

    fn film(&self, iterations: u64) -> Film {
        let (width, height) = (self.scene.film().width, self.scene.film().height);
        let mut film = Film::new(width, height);
        for y in 0..height {
            for x in 0..width {
                let i = (y * width + x) as usize;
                match self.sppm.schedule {
                    RadiusSchedule::Pixel => {
                        film.set_pixel(x, y, self.stats[i].radiance(iterations).as_vec3())
                    }
                    RadiusSchedule::Global => film.add_pixel(
                        i,
                        &self.stats[i].sum,
                        iterations.min(u32::MAX as u64) as u32,
                    ),
                }
            }
        }
        film
    }
}

impl Integrator for Sppm {
    fn render(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Film> {
        let tally = Tally::default();
        let mut passes = SppmPasses {
            sppm: self,
            scene,
            stats: per_pixel(scene),
            angle: pixel_angle(scene),
            tally: &tally,
            started: false,
            camera: Vec::new(),
        };
        let splittable = match self.schedule {
            RadiusSchedule::Global => Ok(()),
            RadiusSchedule::Pixel => Err("sppm splits into parts only with radius_schedule = \
                 \"global\" and a number of iterations (no time): under the pixel schedule each \
                 iteration's radius depends on the photons of the iterations before it, so \
                 iterations cannot be rendered apart"
                .to_string()),
        };
        let film = run_passes(
            "sppm",
            &self.passes,
            ctx,
            splittable,
            "camera sample(s)",
            &mut passes,
        )?;
        self.kernel.check_weights()?;
        Ok(film)
    }

    fn name(&self) -> &str {
        "sppm"
    }

    fn parameters(&self) -> Vec<Parameter> {
        let mut p = self.passes.parameters();
        p.push(match self.initial_radius {
            Some(r) => Parameter::float("initial_radius", r),
            None => Parameter::str("initial_radius", "auto"),
        });
        p.push(Parameter::float("alpha", self.alpha as f32));
        p.extend(self.kernel.parameters());
        p.push(Parameter::str("direct", self.direct.name()));
        p.push(Parameter::str(
            "radius_schedule",
            match self.schedule {
                RadiusSchedule::Pixel => "pixel",
                RadiusSchedule::Global => "global",
            },
        ));
        p.push(Parameter::float(
            "glossy_roughness",
            self.camera.glossy_roughness,
        ));
        p
    }

    fn budget(&self) -> Budget {
        PassBudget::budget("sppm")
    }

    /// The gather radius shrinks with the iterations, and the bias with it.
    fn bias(&self) -> Option<String> {
        Some("more iterations (integrators.sppm.iterations) or a smaller integrators.sppm.initial_radius shrink it".into())
    }

    /// `iteration`: the photons the first iteration stores (those of every iteration are
    /// alike, from their own random streams).
    fn photon_maps(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Vec<PhotonMapView>> {
        let photons = self.iteration_photons(scene, 0, ctx)?;
        Ok(vec![foton_photonmap::view(
            "iteration",
            if self.direct == Direct::Photons {
                "every photon of one iteration"
            } else {
                "one iteration's photons but L D (shadow rays count those)"
            },
            self.passes.photons_per_iteration,
            &photons,
        )])
    }
}

/// Reads the parameters (see the table above).
pub fn create(props: &Properties<'_>, scene: &Scene) -> Result<Box<dyn Integrator>> {
    let passes = PassBudget::read(props, 64, 100_000)?;
    let initial_radius = props.f32_opt("initial_radius")?;
    if let Some(r) = initial_radius
        && !(r > 0.0 && r.is_finite())
    {
        return Err(props.error("initial_radius", format!("must be positive, found {r}")));
    }
    let alpha = props.f32("alpha", 0.7)?;
    if !(alpha > 0.0 && alpha <= 1.0) {
        return Err(props.error("alpha", format!("must be in (0, 1], found {alpha}")));
    }
    let kernel = props.kernel("kernel", "box")?;
    let direct = Direct::read(props)?;
    let schedule = match props.choice("radius_schedule", &["pixel", "global"], "pixel")? {
        "global" => RadiusSchedule::Global,
        _ => RadiusSchedule::Pixel,
    };
    if scene.has_media() {
        return Err(Error::Usage(format!(
            "{}: the scene has participating media, which `sppm` does not render (use `vpm` or `path`)",
            scene.file().display()
        )));
    }
    Ok(Box::new(Sppm {
        passes,
        initial_radius,
        alpha: alpha as f64,
        kernel,
        direct,
        max_depth: scene.render().max_depth,
        camera: CameraWalk::read(props, scene)?,
        schedule,
    }))
}

foton_core::api::declare_integrator!(
    "sppm",
    "stochastic progressive photon mapping (Hachisuka and Jensen)",
    create
);
