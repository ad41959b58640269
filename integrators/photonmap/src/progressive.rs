//! What the progressive integrators (`sppm`, `ppb`, `vcm`) share: the pass loop ([`run_passes`]:
//! iterations or a time budget, a part's share of the passes, Ctrl-C, checkpoints, progress)
//! with the parameters that drive it ([`PassBudget`]), the global radius schedule of Knaus
//! and Zwicker, the automatic first radius from a pixel's footprint, and the gather of one
//! iteration's photons on a disc around a camera path's visible point. Each plugin keeps only
//! its per-pass estimator (a [`Passes`]).

use crate::map::{DISC_THICKNESS, DiscClip, PhotonMap};
use foton_core::api::{
    Budget, Error, Film, NormalizedKernel, Parameter, Progress, Properties, RenderContext, Result,
    Rgb, Sampler, Scene, VisiblePoint, Work, usable, warn_unusable,
};
use glam::{DVec3, Vec2, Vec3};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// How many passes a progressive integrator runs and how many photons each traces: the
/// `iterations`, `time` and `photons_per_iteration` of its table, read and checked here once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassBudget {
    /// Passes to run; `None`: until `time` runs out.
    pub iterations: Option<u64>,
    /// Seconds to run for (with `iterations`, an upper bound on the passes).
    pub time: Option<f64>,
    /// Photons (for `vcm`: light subpaths) each pass traces: the summary's count.
    pub photons_per_iteration: u64,
}

impl PassBudget {
    /// The sampler of the camera sample of pixel `pixel` (row-major index) in pass
    /// `iteration`, on the integrator's own random stream `stream`: its numbers depend on
    /// the pixel and the pass alone (the scene's sampler, stratified over the passes).
    pub fn camera_sampler(
        &self,
        scene: &Scene,
        stream: u64,
        pixel: u64,
        iteration: u64,
    ) -> Sampler {
        let seed = scene.render().seed;
        Sampler::with_keys(
            scene.render().sampler,
            &[seed, stream, pixel, iteration],
            seed,
            pixel,
            iteration as u32,
            self.iterations.unwrap_or(1) as u32,
        )
    }
}

/// Reads a progressive integrator's `time` (seconds, > 0) and `iterations` (>= 1; `default`
/// unless `time` is given alone, then unlimited), with their errors: what `sppm`, `ppb` and
/// `vcm` read alike.
pub fn read_passes(props: &Properties<'_>, default: u64) -> Result<(Option<u64>, Option<f64>)> {
    let time = props.f32_opt("time")?;
    if let Some(t) = time
        && !(t > 0.0 && t.is_finite())
    {
        return Err(props.error(
            "time",
            format!("must be a positive number of seconds, found {t}"),
        ));
    }
    let iterations = if props.has("iterations") || time.is_none() {
        let n = props.u64("iterations", default)?;
        if n == 0 {
            return Err(props.error("iterations", "must be at least 1"));
        }
        Some(n)
    } else {
        None
    };
    Ok((iterations, time.map(f64::from)))
}

impl PassBudget {
    /// Reads `time`, `iterations` (default `iterations` unless `time` is given alone) and
    /// `photons_per_iteration`.
    pub fn read(props: &Properties<'_>, iterations: u64, photons: u64) -> Result<PassBudget> {
        let (iterations, time) = read_passes(props, iterations)?;
        let photons_per_iteration = props.u64("photons_per_iteration", photons)?;
        if photons_per_iteration == 0 {
            return Err(props.error("photons_per_iteration", "must be at least 1"));
        }
        Ok(PassBudget {
            iterations,
            time,
            photons_per_iteration,
        })
    }

    /// The parameters as `Integrator::parameters` lists them.
    pub fn parameters(&self) -> Vec<Parameter> {
        let mut p = Vec::new();
        if let Some(n) = self.iterations {
            p.push(Parameter::int("iterations", n));
        }
        if let Some(t) = self.time {
            p.push(Parameter::float("time", t));
        }
        p.push(Parameter::int(
            "photons_per_iteration",
            self.photons_per_iteration,
        ));
        p
    }

    /// `foton compare --time` counts a progressive integrator's work in passes.
    pub fn budget(plugin: &str) -> Budget {
        Budget {
            work: Work::Iterations {
                key: format!("integrators.{plugin}.iterations"),
            },
            scaled: Vec::new(),
        }
    }

    /// The passes `[first, last)` this render runs: all of them (`last` `None` with a time
    /// budget), or the part's share. Passes are split into parts only with a number of
    /// iterations and no time, and only if `splittable` (else its reason, the error).
    fn range(
        &self,
        plugin: &str,
        ctx: &RenderContext<'_>,
        splittable: std::result::Result<(), String>,
    ) -> Result<(u64, Option<u64>)> {
        if ctx.part.is_whole() {
            return Ok((0, self.iterations));
        }
        let part = ctx.part;
        splittable.map_err(|why| Error::Render(format!("part {part}: {why}")))?;
        let Some(n) = self.iterations.filter(|_| self.time.is_none()) else {
            return Err(Error::Render(format!(
                "part {part}: {plugin} splits into parts only with a number of iterations (no time)"
            )));
        };
        let share = part.share(n);
        Ok((share.start, Some(share.end)))
    }
}

/// A progressive integrator's passes: what one pass adds to the pixels, and the image they
/// make. The loop around them is [`run_passes`].
pub trait Passes {
    /// Runs pass `iteration` (0-based: the same number whichever part runs it) and adds its
    /// estimates to the pixels. `Ok(None)` when the render was cancelled before the pass was
    /// complete: nothing is added (a pass with part of its photons would be biased).
    /// Otherwise the progress bar's status line. `quiet` is the context for work that
    /// should not report progress of its own (the photon pass).
    fn pass(&mut self, iteration: u64, quiet: &RenderContext<'_>) -> Result<Option<String>>;

    /// The image after `passes` passes (each pixel's mean over them).
    fn film(&self, passes: u64) -> Film;

    /// What the passes have counted so far.
    fn tally(&self) -> &Tally;
}

/// What the passes count across threads: rays, and estimates, photon contributions or splats
/// (light paths connected to the camera) that were not finite and non-negative (left out: one
/// would stay in a pixel's sum for the rest of the render).
#[derive(Debug, Default)]
pub struct Tally {
    pub rays: AtomicU64,
    pub bad_samples: AtomicU64,
    pub bad_photons: AtomicU64,
    pub bad_splats: AtomicU64,
}

impl Tally {
    pub fn add(counter: &AtomicU64, n: u64) {
        if n > 0 {
            counter.fetch_add(n, Ordering::Relaxed);
        }
    }
}

/// The progress of a pass's inner work: only its phase timings go to the host (the bar and
/// messages are the passes' own).
struct PhasesOnly<'a>(&'a dyn Progress);

impl Progress for PhasesOnly<'_> {
    fn begin(&self, _: &str, _: u64) {}
    fn advance(&self, _: u64) {}
    fn finish(&self) {}
    fn warn(&self, _: &str) {}
    fn phase(&self, name: &str, wall: Duration, cpu: Duration) {
        self.0.phase(name, wall, cpu);
    }
}

/// The pass loop of a progressive integrator: runs the passes `budget` and the part ask for
/// (until `time` runs out with a time budget, or Ctrl-C), reports progress, writes
/// checkpoints (`--checkpoint`: the image after the passes so far), and returns the image of
/// the passes done with its counts (part, iterations, rays, photons). The caller checks its
/// kernel's weights after it. `samples` names what
/// a bad pixel estimate is in the warnings; `splittable` says whether the passes may be split
/// into parts (passes independent of each other).
pub fn run_passes(
    plugin: &str,
    budget: &PassBudget,
    ctx: &RenderContext<'_>,
    splittable: std::result::Result<(), String>,
    samples: &str,
    passes: &mut impl Passes,
) -> Result<Film> {
    let (first, last) = budget.range(plugin, ctx, splittable)?;
    let start = Instant::now();
    let phases = PhasesOnly(ctx.progress);
    let quiet = RenderContext::new(ctx.threads, ctx.cancel, &phases);
    match (last, budget.time) {
        (Some(n), None) => ctx.progress.begin("iterations", n - first),
        (_, Some(t)) => ctx.progress.begin("seconds", t.ceil() as u64),
        (None, None) => unreachable!("PassBudget::read sets one"),
    }
    let mut done = first;
    let mut seconds_reported = 0u64;
    let mut rays_reported = 0u64;
    loop {
        if last.is_some_and(|n| done >= n)
            || budget
                .time
                .is_some_and(|t| start.elapsed().as_secs_f64() >= t)
            || ctx.cancelled()
        {
            break;
        }
        let Some(status) = passes.pass(done, &quiet)? else {
            break;
        };
        done += 1;
        ctx.progress.status(&status);
        let rays = passes.tally().rays.load(Ordering::Relaxed);
        ctx.progress.rays(rays - rays_reported);
        rays_reported = rays;
        match budget.time {
            None => ctx.progress.advance(1),
            Some(_) => {
                let s = start.elapsed().as_secs();
                ctx.progress.advance(s - seconds_reported);
                seconds_reported = s;
            }
        }
        let kept = done - first;
        ctx.progress.checkpoint(kept, &|| passes.film(kept));
    }
    ctx.progress.finish();
    let tally = passes.tally();
    let bad = tally.bad_samples.load(Ordering::Relaxed);
    warn_unusable(ctx, bad, samples, "replaced by zero");
    let bad = tally.bad_photons.load(Ordering::Relaxed);
    warn_unusable(ctx, bad, "photon contribution(s)", "left out");
    let bad = tally.bad_splats.load(Ordering::Relaxed);
    warn_unusable(ctx, bad, "splat(s)", "dropped");
    let mut film = passes.film(done - first);
    film.part = ctx.part;
    film.rays = tally.rays.load(Ordering::Relaxed);
    film.iterations = done - first;
    film.iterations_planned = last.map_or(0, |n| n - first);
    film.photons = (done - first) * budget.photons_per_iteration;
    Ok(film)
}

/// Knaus and Zwicker's radius schedule: the factor prod_{j=1}^{i-1} (j + alpha) / (j + 1) of
/// iteration i (1-based). It falls like i^(alpha - 1). Applied to r^2 for a 2-D kernel
/// (surfaces: r_i^2 = r_1^2 x factor) and to r for a 1-D kernel (photon beams, Jarosz et al.
/// 2011: r_i = r_1 x factor): in both the kernel's support, and with it the photons an
/// iteration gathers, shrinks by the factor, slowly enough that the average over iterations
/// converges: variance and bias both vanish.
pub fn global_radius2_scale(iteration: u64, alpha: f64) -> f64 {
    (1..iteration).fold(1.0, |s, j| s * (j as f64 + alpha) / (j as f64 + 1.0))
}

/// One `T::default()` per pixel of the scene's film, in row order: a progressive
/// integrator's per-pixel state.
pub fn per_pixel<T: Clone + Default>(scene: &Scene) -> Vec<T> {
    vec![T::default(); scene.film().width as usize * scene.film().height as usize]
}

/// The angle one pixel subtends at the centre of the image.
pub fn pixel_angle(scene: &Scene) -> f32 {
    let (w, h) = (scene.film().width as f32, scene.film().height as f32);
    let a = scene.camera().generate_ray(Vec2::new(w / 2.0, h / 2.0)).dir;
    let b = scene
        .camera()
        .generate_ray(Vec2::new(w / 2.0, h / 2.0 + 1.0))
        .dir;
    a.dot(b).clamp(-1.0, 1.0).acos()
}

/// The automatic first gather radius of a pixel whose visible point lies `distance` along
/// the camera path: `footprints` times the pixel's footprint there (an orthographic camera's
/// pixel width at any distance), kept within [1/1000, 1/50]
/// of the scene's bounding-box diagonal (a few pixels wide, so that early iterations find
/// photons, and small against the scene; an infinite distance gets the largest). `sppm` takes
/// 3 footprints ([`SPPM_FOOTPRINTS`]); `ppb`, whose passes gather from many more surface
/// photons, fewer (its README).
pub fn auto_radius(scene: &Scene, pixel_angle: f32, distance: f32, footprints: f64) -> f64 {
    let diagonal = (scene.bounds().1 - scene.bounds().0).length().max(1e-6) as f64;
    let footprint = match scene.camera().orthographic_pixel() {
        Some(width) => footprints * width as f64,
        None => footprints * pixel_angle as f64 * distance as f64,
    };
    footprint.clamp(diagonal / 1000.0, diagonal / 50.0)
}

/// `sppm`'s automatic first radius in pixel footprints.
pub const SPPM_FOOTPRINTS: f64 = 3.0;

/// One gather: the (kernel-weighted) photon count and the reflected flux.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Gathered {
    /// Weighted count M: each photon counts w = pi r^2 K(d, r) (1 for the box).
    pub m: f64,
    /// Reflected flux Phi = sum_p f(x, w_p, w) Phi_p w_p (not weighted by the path's
    /// throughput).
    pub phi: DVec3,
    /// Contributions that were not finite and non-negative, left out.
    pub bad: u64,
}

/// Gathers the photons of `map` within `r` of the visible point `vp` that lie on a disc of
/// its surface: the same side (stored normal within about 25 degrees of the point's), no
/// farther from the tangent plane than [`DISC_THICKNESS`] of r, and of at most `depth`
/// scattering events.
pub fn gather_disc(
    map: &PhotonMap,
    vp: &VisiblePoint,
    r: f32,
    depth: u32,
    kernel: &NormalizedKernel,
) -> Gathered {
    gather(map, vp, r, depth, kernel, |_| true)
}

/// [`gather_disc`] with the disc clipped at the walls around the visible point
/// ([`DiscClip`]: beside a crease the disc reaches behind the wall, where no photon of this
/// surface lands), and the fraction of the kernel's mass left on the point's side, by which
/// the caller divides the disc's area. Where no wall is within r, [`gather_disc`] itself and
/// coverage 1: the estimate changes only beside walls.
pub fn gather_disc_clipped(
    map: &PhotonMap,
    vp: &VisiblePoint,
    r: f32,
    depth: u32,
    kernel: &NormalizedKernel,
    clip: &DiscClip,
) -> (Gathered, f32) {
    let coverage = clip.coverage(r, kernel);
    if coverage == 1.0 {
        return (gather_disc(map, vp, r, depth, kernel), 1.0);
    }
    (
        gather(map, vp, r, depth, kernel, |x| clip.keeps(x)),
        coverage,
    )
}

#[inline(always)]
fn gather(
    map: &PhotonMap,
    vp: &VisiblePoint,
    r: f32,
    depth: u32,
    kernel: &NormalizedKernel,
    keeps: impl Fn(Vec3) -> bool,
) -> Gathered {
    let disc = std::f32::consts::PI * r * r;
    let thickness = DISC_THICKNESS * r;
    let mut g = Gathered::default();
    map.within(vp.hit.p, r, |photon, d2| {
        if photon.depth() > depth
            || photon.normal().dot(vp.n) <= 0.9
            || (photon.position - vp.hit.p).dot(vp.n).abs() > thickness
            || !keeps(photon.position)
        {
            return; // too long, another surface, its other side, or behind a wall
        }
        let w = kernel.weight_2d(d2.sqrt(), r) * disc;
        let f = vp.bsdf.eval_density(vp.wo, photon.wi());
        let flux: Rgb = f * photon.power() * w;
        if !(usable(flux) && w.is_finite() && w >= 0.0) {
            g.bad += 1;
            return;
        }
        g.m += w as f64;
        g.phi += flux.as_dvec3();
    });
    g
}
