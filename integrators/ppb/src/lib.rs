//! # `ppb`: progressive photon beams (Jarosz, Nowrouzezahrai, Thomas, Sloan and Zwicker 2011)
//!
//! This table is the one list of the parameters (`[integrators.ppb]`); the README, the
//! scene-format page and docs/photon-mapping.md point here. "diagonal" is the scene's
//! bounding-box diagonal.
//!
//! | parameter               | type    | meaning                                                   | default |
//! |-------------------------|---------|-----------------------------------------------------------|---------|
//! | `iterations`            | integer | passes (photon beams + one camera sample per pixel) to run, >= 1 | 32 (unlimited with `time`) |
//! | `time`                  | float   | run until this many seconds have passed, > 0              | none    |
//! | `photons_per_iteration` | integer | photons emitted in each pass for the photon beams, >= 1   | 2500    |
//! | `surface_photons`       | integer | photons emitted in each pass for the surface estimate, >= `photons_per_iteration` (equal: the beams' own photons, one trace) | 100000 (or `photons_per_iteration` if larger) |
//! | `initial_beam_radius`   | float   | the photon beams' width r_1 in the first pass (world units), > 0 | 0.0287 x diagonal x photons_per_iteration^(-1/5) |
//! | `initial_radius`        | float   | the surface gather radius of the first pass, > 0          | automatic: 3 pixel footprints (`sppm`'s) at the pass's visible point, within [1/1000, 1/50] of the diagonal |
//! | `alpha`                 | float   | the radius schedule's exponent, in (0, 1)                 | 0.7     |
//! | `beam_type`             | string  | `short` (a beam ends at the photon's next scattering event) or `long` (at the next surface, with the transmittance along it) | `short` |
//! | `kernel`                | string  | `box`, `cone`, `gaussian` or a kernel plugin's name (normalised in 1-D across beams, in 2-D on surfaces) | `box` |
//! | `cone_c`                | float   | the cone kernel's c >= 1 (read only with `kernel = "cone"`) | 1     |
//! | `direct`                | string  | direct light at surfaces: `nee` (shadow rays) or `photons` | `nee`  |
//! | `glossy_roughness`      | float   | glossy lobes smoother than this (microfacet alpha) are followed by the camera pass, not estimated (docs/photon-mapping.md, "Glossy surfaces") | 0.5 |
//!
//! `[render] max_depth` bounds the scattering events of whole light paths; `[render] spp` is
//! not used (each pass takes one new camera sample per pixel). With `time`, `iterations` (if
//! given) is an upper bound. For `foton compare --time` the work is counted in iterations
//! (`integrators.ppb.iterations`); `foton photons` draws one pass's surface photons
//! (`iteration`) and the starts of its beams (`beams`).
//!
//! **A pass** (iteration i = 1, 2, ...) traces `photons_per_iteration` photons from their own
//! random streams (foton-photonmap's photon pass). Their flights through media are recorded
//! as photon beams (foton-photonmap's `beams`: `beam_type`), every one of them, first flights
//! from the lights included: in a medium, beams count all scattered light, single scattering
//! too. At diffuse surfaces the photons are stored as in `sppm` (all but L D with `direct =
//! "nee"`). Then each pixel takes one camera path (core's `walk_to_diffuse`, through null
//! boundaries, media and delta surfaces): along each medium segment the beam x beam estimate
//!
//! ```text
//! sum_b Phi_b W_b(t_b) sigma_s(x_c) p(w_b . -w) Tr(x, x_c) K1(u_b, r_i) / sin(theta_b)
//! ```
//!
//! (foton-photonmap's `beams` module derives it; the candidate beams of a segment still on
//! the camera's primary ray come from the pass's screen bins, foton-photonmap's `screen`, those
//! of later segments from the beams' BVH: the same crossings), at the visible point emission, direct light
//! by a shadow ray (`direct = "nee"`) and the photons of the disc of radius R_i around it
//! (`sppm`'s gather, shared in foton-photonmap's `progressive`, with the disc clipped at the
//! walls that eight probe rays in the tangent plane find: foton-photonmap's `DiscClip`), each
//! weighted by the throughput before it. The pixel's value is the mean of its passes' estimates.
//!
//! **Radii** (Knaus and Zwicker 2011's probabilistic analysis, which Jarosz et al. 2011 apply
//! to beams): pass i uses
//!
//! ```text
//! r_i = r_1 prod_{j=1}^{i-1} (j + alpha) / (j + 1)        (beams: a 1-D kernel)
//! R_i^2 = R_1^2 prod_{j=1}^{i-1} (j + alpha) / (j + 1)    (surfaces: a 2-D kernel)
//! ```
//!
//! The 1-D estimate's variance grows as 1 / r and its bias as r^2, so the beam width itself
//! (not its square) shrinks by the factor: the variance of pass i grows like i^(1 - alpha),
//! slowly enough that the mean over n passes has variance ~ n^(-alpha), while its bias falls
//! like n^(2 (alpha - 1)). **Why alpha = 0.7**: balancing the two gives the best asymptotic
//! rate at alpha = 4/5 for beams and 2/3 for surfaces (squared error ~ n^(-4/5) and n^(-2/3));
//! one alpha serves both here, and 0.7 lies between them (`sppm`'s default too), losing
//! little on either. R_1 is the automatic radius of the pass's own visible point (or
//! `initial_radius`), so passes are independent: any subset can be rendered apart and
//! averaged (`foton render --part`, `foton merge`), and the sums are exact, so the parts
//! merge into the whole render bit for bit.
//!
//! **Why 2500 beam photons and 100000 surface photons a pass** (measured: the README's
//! table). A camera ray's cost grows with the beams' total length times their width, and the
//! width starts at the 1-D optimum for the pass's photons, so the cost of a pass is nearly
//! proportional to its beam photons (to the power 4/5); surface photons cost only their
//! tracing and a disc gather per pixel. On the fog scenes the worst 16 x 16 blocks were never
//! in the fog: they were the dim surfaces lit by indirect light alone (the ceiling) and the
//! corners, where a disc reaches past the wall's edge. With the beams' photons alone at the
//! surfaces (5000 a pass) the ceiling's noise decided the image (worst block 12.8 % on the
//! foggy Cornell box at 256 x 256, whatever the beams' width or kind); 100000 surface photons
//! take its noise away for about a tenth more time, and then a smaller first radius (1.25
//! footprints instead of `sppm`'s 3) took the corners' bias down. The beams then afford
//! fewer photons (2500): the same error in three quarters of the time. With the disc
//! clipped at the walls (no corner bias to trade against), the first radius is
//! `sppm`'s 3 footprints again: the surfaces' noise, which decided the per-pixel error
//! (more surface photons or a wider disc took it down; narrower beams raised it), falls by a
//! half to two thirds (README). With the screen bins for the primary rays a pass's beam
//! gather costs a third less; at equal CPU time on the volumetric caustic 5000 beam
//! photons, or 50000 or 200000 surface photons, gave no lower error than these (README), so
//! they stay.
//!
//! **Each light path once**: in media by the beams (a light path scattering at x_c on the
//! camera ray is the photon's path up to its beam plus that event), at surfaces L D by shadow
//! rays (or photons) and everything else by the surface photons, which include those that
//! scattered in media on the way. Camera rays leaving the scene in a medium are followed to
//! the box around the scene (beams end there too).
//!
//! **Determinism**: photons and camera samples draw from streams keyed by the pass, the
//! photon and the pixel; the beam BVH, the screen bins (in piece order) and the kd-tree are
//! built in a fixed order; images are
//! identical for any number of threads and any split into parts. Memory holds one pass's
//! photons and beams at a time.
//!
//! `foton render --techniques` keeps the terms apart as layers of the film (docs/tools.md),
//! summing to the image: `emission`, `beam` (the photon beams in media), `direct` (shadow
//! rays) and `surface` (the surface photons).

use foton_core::api::{
    Budget, CameraWalk, Direct, Film, Integrator, Mis, NormalizedKernel, Parameter, PhotonMapView,
    Properties, RadianceSum, RenderContext, Result, Rgb, Sampler, Scatter, Scene, Segment, Vec3,
    estimate_direct, splitmix64, usable, walk_to_diffuse, with_pool,
};
use foton_photonmap::beams::{
    Beam, BeamKind, BeamMap, Kernel1d, default_beam_radius, exit_distance, read_beam_type,
};
use foton_photonmap::map::{CLIP_PROBES, DiscClip, Photon, PhotonMap};
use foton_photonmap::progressive::{
    PassBudget, Passes, SPPM_FOOTPRINTS, Tally, auto_radius, gather_disc_clipped,
    global_radius2_scale, per_pixel, pixel_angle, run_passes,
};
use foton_photonmap::screen::ScreenBeams;
use foton_photonmap::trace::{
    PathClass, STREAM_GLOBAL, Site, TraceOptions, trace_photons, trace_photons_and_beams,
};
use rayon::prelude::*;

pub struct Ppb {
    /// `iterations`, `time`, `photons_per_iteration`.
    pub passes: PassBudget,
    /// Photons traced for the surface estimate in each pass (the beams' own, or more).
    pub surface_photons: u64,
    pub initial_beam_radius: f32,
    pub initial_radius: Option<f32>,
    pub alpha: f64,
    pub beam_type: BeamKind,
    pub kernel: NormalizedKernel,
    /// The kernel's 1-D normalisation (`Kernel1d::norm`).
    pub kernel_1d: f32,
    pub direct: Direct,
    pub max_depth: u32,
    /// How camera paths treat glossy surfaces.
    pub camera: CameraWalk,
}

/// Random stream of the camera passes.
const STREAM_CAMERA: u64 = 0x7070_6263;

/// The automatic first surface radius in pixel footprints: `sppm`'s (README: measured).
pub const FOOTPRINTS: f64 = SPPM_FOOTPRINTS;

/// Random stream of the surface photons when they are a trace of their own.
const STREAM_SURFACE: u64 = 0x7070_6273;

/// One pass's photons: the surface map and the beams with this pass's width.
struct Pass {
    surface: PhotonMap,
    beams: BeamMap,
    /// The beams' pieces binned by the pixels whose primary rays may accept them.
    screen: ScreenBeams,
    /// R_i / R_1 for the surface gather.
    surface_shrink: f64,
    /// The angle one pixel subtends (for the automatic first radius).
    pixel_angle: f32,
}

impl Ppb {
    /// The photons pass `iteration` (0-based) stores at surfaces, and its beams. With as many
    /// surface photons as beam photons one trace gives both; with more, the surface photons
    /// are a trace of their own (another random stream), the beams' trace stores none.
    fn trace(
        &self,
        scene: &Scene,
        iteration: u64,
        ctx: &RenderContext<'_>,
    ) -> Result<(Vec<Photon>, Vec<Beam>)> {
        let options = |photons, stream| TraceOptions {
            photons,
            max_depth: self.max_depth,
            seed: splitmix64(scene.render().seed ^ splitmix64(iteration)),
            stream,
            stop_at_diffuse: false,
            sobol_emission: TraceOptions::emission_for(scene.render().sampler),
        };
        let keep_direct = self.direct == Direct::Photons;
        let shared = self.surface_photons == self.passes.photons_per_iteration;
        let (mut lists, beams) = trace_photons_and_beams(
            scene,
            &options(self.passes.photons_per_iteration, STREAM_GLOBAL),
            ctx,
            1,
            |site, class| {
                (shared && site == Site::Surface && (class != PathClass::Direct || keep_direct))
                    .then_some(0)
            },
            scene.has_media().then_some(self.beam_type),
            |_| true,
        )?;
        if !shared {
            lists = trace_photons(
                scene,
                &options(self.surface_photons, STREAM_SURFACE),
                ctx,
                1,
                |site, class| {
                    (site == Site::Surface && (class != PathClass::Direct || keep_direct))
                        .then_some(0)
                },
            )?;
        }
        Ok((lists.pop().unwrap_or_default(), beams))
    }

    fn pass(&self, scene: &Scene, iteration: u64, ctx: &RenderContext<'_>) -> Result<Pass> {
        let (photons, beams) = self.trace(scene, iteration, ctx)?;
        let scale = global_radius2_scale(iteration + 1, self.alpha);
        let r = (self.initial_beam_radius as f64 * scale) as f32;
        let _build = ctx.phase("beam and photon map build");
        let margin = scene.film().filter.margin();
        with_pool(ctx.threads, || {
            let ((beams, screen), surface) = rayon::join(
                || {
                    let beams = BeamMap::build(beams, r);
                    let screen = ScreenBeams::build(&beams, scene.camera(), margin);
                    (beams, screen)
                },
                || PhotonMap::build(photons),
            );
            Pass {
                surface,
                screen,
                beams,
                surface_shrink: scale.sqrt(),
                pixel_angle: pixel_angle(scene),
            }
        })
    }

    /// Pass `iteration`'s estimate of the radiance through pixel `pixel` at (x, y); `share`
    /// gets each term with its technique (`EMISSION`, `BEAM`, `DIRECT`, `SURFACE`), weighted
    /// by the camera path's throughput (their sum is the estimate, to float rounding). Also
    /// returns the camera sample's filter weight, by which the caller multiplies the estimate
    /// and its shares once it has found the estimate usable (exactly 1.0 for a positive
    /// filter).
    #[allow(clippy::too_many_arguments)]
    fn estimate(
        &self,
        scene: &Scene,
        pass: &Pass,
        iteration: u64,
        (x, y): (u32, u32),
        rays: &mut u64,
        bad_photons: &mut u64,
        mut share: impl FnMut(usize, Rgb),
    ) -> (Rgb, f32) {
        let pixel = y as u64 * scene.film().width as u64 + x as u64;
        let mut sampler = self
            .passes
            .camera_sampler(scene, STREAM_CAMERA, pixel, iteration);
        let placed = scene.film().filter.sample(x, y, sampler.next_2d());
        let film = placed.film;

        let ray = scene.camera().generate_ray_lens(film, || sampler.next_2d());
        let kernel = Kernel1d::with_norm(&self.kernel, self.kernel_1d);
        // A segment that leaves the scene in a medium (unbounded fog, a camera in it) meets
        // beams as far as photons went: the box around the scene and the pass's beams.
        let grow = Vec3::splat(pass.beams.radius());
        let (lo, hi) = pass.beams.bounds();
        let bounds = (
            scene.bounds().0.min(lo) - grow,
            scene.bounds().1.max(hi) + grow,
        );
        let path = walk_to_diffuse(
            scene,
            ray,
            self.camera,
            &mut sampler,
            rays,
            |seg: &Segment, _m, bounces: u32, _: &mut Sampler, _: &mut u64| {
                // The scattering event on the camera ray is one of the light path's.
                let Some(medium) = seg.medium.filter(|_| bounces < self.max_depth) else {
                    return Rgb::ZERO;
                };
                let start = seg.start();
                let t_end = if seg.hit.is_some() {
                    seg.length()
                } else {
                    exit_distance(&start, bounds)
                };
                if t_end.is_nan() || t_end <= 0.0 {
                    return Rgb::ZERO;
                }
                let depth = self.max_depth - bounces;
                if bounces == 0 {
                    // Still on the primary ray through `film` (null boundaries keep the
                    // direction): the screen's bins give the candidates.
                    pass.beams.in_scattered_primary(
                        scene,
                        &kernel,
                        &pass.screen,
                        film,
                        &start,
                        t_end,
                        medium,
                        depth,
                    )
                } else {
                    pass.beams
                        .in_scattered(scene, &kernel, &start, t_end, medium, depth)
                }
            },
        );
        let mut l = path.emitted;
        share(EMISSION, path.emission);
        share(BEAM, path.in_scattered);
        if let Some(vp) = &path.visible {
            let mut lv = Rgb::ZERO;
            if self.direct == Direct::ShadowRays {
                let at = Scatter::Surface {
                    hit: &vp.hit,
                    bsdf: &vp.bsdf,
                };
                let direct = estimate_direct(
                    scene,
                    at,
                    vp.wo,
                    vp.medium,
                    Mis::LightOnly,
                    &mut sampler,
                    rays,
                );
                lv += direct;
                share(DIRECT, vp.beta * direct);
            }
            let r1 = match self.initial_radius {
                Some(r) => r as f64,
                None => auto_radius(scene, pass.pixel_angle, vp.distance, FOOTPRINTS),
            };
            let r = (r1 * pass.surface_shrink) as f32;
            *rays += CLIP_PROBES as u64;
            let clip = DiscClip::probe(scene, vp.hit.p, vp.n, r);
            let depth = self.max_depth - vp.bounces;
            let (g, coverage) =
                gather_disc_clipped(&pass.surface, vp, r, depth, &self.kernel, &clip);
            *bad_photons += g.bad;
            let disc = std::f64::consts::PI * (r as f64) * (r as f64) * coverage as f64;
            let gathered = (g.phi / disc).as_vec3();
            lv += gathered;
            share(SURFACE, vp.beta * gathered);
            l += vp.beta * lv;
        }
        (l, placed.weight)
    }
}

/// The passes of one render: each pixel's exact sum of its passes' estimates, one sample per
/// pass.
struct PpbPasses<'a> {
    ppb: &'a Ppb,
    scene: &'a Scene,
    sums: Vec<RadianceSum>,
    /// With `--techniques`: per pixel, each technique's sum; empty otherwise.
    layer_sums: Vec<[RadianceSum; 4]>,
    tally: &'a Tally,
}

impl Passes for PpbPasses<'_> {
    fn pass(&mut self, iteration: u64, quiet: &RenderContext<'_>) -> Result<Option<String>> {
        let (ppb, scene) = (self.ppb, self.scene);
        let pass = ppb.pass(scene, iteration, quiet)?;
        if quiet.cancelled() {
            return Ok(None);
        }
        let width = scene.film().width as usize;
        let _camera = quiet.phase("camera pass");
        let camera = CameraPass {
            ppb,
            scene,
            tally: self.tally,
            pass: &pass,
            iteration,
        };
        let (sums, layer_sums) = (&mut self.sums, &mut self.layer_sums);
        with_pool(quiet.threads, || {
            if layer_sums.is_empty() {
                sums.par_chunks_mut(width)
                    .enumerate()
                    .for_each(|(y, row)| camera.row(y, row, None));
            } else {
                sums.par_chunks_mut(width)
                    .zip(layer_sums.par_chunks_mut(width))
                    .enumerate()
                    .for_each(|(y, (row, layers))| camera.row(y, row, Some(layers)));
            }
        })?;
        let photons = (iteration + 1) * ppb.passes.photons_per_iteration;
        Ok(Some(format!(
            "iteration {}, {photons} photons, {} beams of width {:.5}",
            iteration + 1,
            pass.beams.len(),
            pass.beams.radius()
        )))
    }

    fn tally(&self) -> &Tally {
        self.tally
    }

    fn film(&self, passes: u64) -> Film {
        let (width, height) = (self.scene.film().width, self.scene.film().height);
        let mut film = Film::new(width, height);
        let count = passes.min(u32::MAX as u64) as u32;
        for (i, sum) in self.sums.iter().enumerate() {
            film.add_pixel(i, sum, count);
        }
        if !self.layer_sums.is_empty() {
            for name in TECHNIQUES {
                film.add_layer(name);
            }
            for (i, sums) in self.layer_sums.iter().enumerate() {
                for (k, s) in sums.iter().enumerate() {
                    film.add_layer_pixel(k, i, s);
                }
            }
        }
        film
    }
}

/// One pass's camera pass over the pixels.
struct CameraPass<'a> {
    ppb: &'a Ppb,
    scene: &'a Scene,
    tally: &'a Tally,
    pass: &'a Pass,
    iteration: u64,
}

impl CameraPass<'_> {
    /// Row `y`: each pixel's estimate added to `row` and, with `--techniques`, its
    /// techniques' shares to `layers` (a sample that is not usable is dropped from both).
    fn row(&self, y: usize, row: &mut [RadianceSum], mut layers: Option<&mut [[RadianceSum; 4]]>) {
        let (mut rays, mut bad, mut unusable) = (0u64, 0u64, 0u64);
        for (x, sum) in row.iter_mut().enumerate() {
            let mut shares = [Rgb::ZERO; 4];
            let keep = layers.is_some();
            let (l, weight) = self.ppb.estimate(
                self.scene,
                self.pass,
                self.iteration,
                (x as u32, y as u32),
                &mut rays,
                &mut bad,
                |k, v| {
                    if keep {
                        shares[k] += v
                    }
                },
            );
            if usable(l) {
                // The camera sample's filter weight, after the check (it may be negative):
                // exactly 1.0 for a positive filter.
                sum.add(l * weight);
                if let Some(layers) = layers.as_deref_mut() {
                    for (layer, v) in layers[x].iter_mut().zip(shares) {
                        layer.add(v * weight);
                    }
                }
            } else {
                unusable += 1;
            }
        }
        Tally::add(&self.tally.rays, rays);
        Tally::add(&self.tally.bad_photons, bad);
        Tally::add(&self.tally.bad_samples, unusable);
    }
}

/// The layers of `foton render --techniques`: emission met by the camera walk (and the direct
/// light of the glossy vertices it follows), the photon beams' estimate along the camera
/// rays through media, direct light by shadow rays at the visible surface point, and the
/// surface photons' estimate there.
const TECHNIQUES: [&str; 4] = ["emission", "beam", "direct", "surface"];
const EMISSION: usize = 0;
const BEAM: usize = 1;
const DIRECT: usize = 2;
const SURFACE: usize = 3;

impl Integrator for Ppb {
    fn render(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Film> {
        let tally = Tally::default();
        let mut passes = PpbPasses {
            ppb: self,
            scene,
            sums: per_pixel(scene),
            layer_sums: match ctx.techniques {
                Some(_) => per_pixel(scene),
                None => Vec::new(),
            },
            tally: &tally,
        };
        // Passes are independent (r_1 from each pass's own visible point): any split works.
        let film = run_passes(
            "ppb",
            &self.passes,
            ctx,
            Ok(()),
            "pass estimate(s)",
            &mut passes,
        )?;
        self.kernel.check_weights()?;
        Ok(film)
    }

    fn name(&self) -> &str {
        "ppb"
    }

    /// `emission`, `beam` (the photon beams in media), `direct` (shadow rays at the visible
    /// surface point; black with `direct = "photons"`) and `surface` (the surface photons).
    fn techniques(&self, _depth: u32) -> Vec<String> {
        TECHNIQUES.map(String::from).to_vec()
    }

    fn parameters(&self) -> Vec<Parameter> {
        let mut p = self.passes.parameters();
        p.push(Parameter::int("surface_photons", self.surface_photons));
        p.push(Parameter::float(
            "initial_beam_radius",
            self.initial_beam_radius,
        ));
        p.push(match self.initial_radius {
            Some(r) => Parameter::float("initial_radius", r),
            None => Parameter::str("initial_radius", "auto"),
        });
        p.push(Parameter::float("alpha", self.alpha as f32));
        p.push(Parameter::str("beam_type", self.beam_type.name()));
        p.extend(self.kernel.parameters());
        p.push(Parameter::str("direct", self.direct.name()));
        p.push(Parameter::float(
            "glossy_roughness",
            self.camera.glossy_roughness,
        ));
        p
    }

    fn budget(&self) -> Budget {
        PassBudget::budget("ppb")
    }

    /// The beams' width and the surface radius shrink with the passes, and the bias with them.
    fn bias(&self) -> Option<String> {
        Some("more iterations (integrators.ppb.iterations) or a smaller integrators.ppb.initial_beam_radius and integrators.ppb.initial_radius shrink it".into())
    }

    /// `iteration`: the surface photons of the first pass; `beams`: the starts of its beams.
    fn photon_maps(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Vec<PhotonMapView>> {
        let (photons, beams) = self.trace(scene, 0, ctx)?;
        let starts: Vec<Photon> = beams.iter().map(|b| b.as_photon()).collect();
        Ok(vec![
            foton_photonmap::view(
                "iteration",
                "one pass's surface photons (but L D with direct = \"nee\")",
                self.surface_photons,
                &photons,
            ),
            foton_photonmap::view(
                "beams",
                "the starts of one pass's photon beams",
                self.passes.photons_per_iteration,
                &starts,
            ),
        ])
    }
}

/// Reads the parameters (see the table above).
pub fn create(props: &Properties<'_>, scene: &Scene) -> Result<Box<dyn Integrator>> {
    let diagonal = foton_photonmap::surface::diagonal(scene);
    let passes = PassBudget::read(props, 32, 2_500)?;
    let positive_opt = |key: &str| -> Result<Option<f32>> {
        let r = props.f32_opt(key)?;
        if let Some(r) = r
            && !(r > 0.0 && r.is_finite())
        {
            return Err(props.error(key, format!("must be positive, found {r}")));
        }
        Ok(r)
    };
    let surface_photons =
        props.u64("surface_photons", passes.photons_per_iteration.max(100_000))?;
    if surface_photons < passes.photons_per_iteration {
        return Err(props.error(
            "surface_photons",
            format!(
                "must be at least photons_per_iteration ({}), found {surface_photons}",
                passes.photons_per_iteration
            ),
        ));
    }
    let initial_beam_radius = positive_opt("initial_beam_radius")?
        .unwrap_or_else(|| default_beam_radius(diagonal, passes.photons_per_iteration));
    let initial_radius = positive_opt("initial_radius")?;
    let alpha = props.f32("alpha", 0.7)?;
    if !(alpha > 0.0 && alpha < 1.0) {
        return Err(props.error("alpha", format!("must be in (0, 1), found {alpha}")));
    }
    let beam_type = read_beam_type(props)?;
    let kernel = props.kernel("kernel", "box")?;
    let kernel_1d = Kernel1d::norm(&kernel);
    let direct = Direct::read(props)?;
    Ok(Box::new(Ppb {
        passes,
        surface_photons,
        initial_beam_radius,
        initial_radius,
        alpha: alpha as f64,
        beam_type,
        kernel,
        kernel_1d,
        direct,
        max_depth: scene.render().max_depth,
        camera: CameraWalk::read(props, scene)?,
    }))
}

foton_core::api::declare_integrator!("ppb", "progressive photon beams (Jarosz et al.)", create);
