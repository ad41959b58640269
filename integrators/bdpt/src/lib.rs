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
//!   the pixel it lands on (a splat: `foton_core::api::render_pixels_splatting`), light
//!   tracing; s = 1, t = 1 is an area light's point seen directly;
//! * s, t >= 2: a light vertex and a camera vertex connected.
//!
//! The strategies are combined by the power heuristic, their weights computed in O(1) per
//! connection from two running quantities per vertex (SmallVCM's `dVCM` and `dVC`, module
//! `foton_bidir::mis`). Vertices on delta surfaces (mirror, smooth glass; the smooth coat of a plastic when
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
//! Participating media along both subpaths (as Mitsuba 0.6's `bdpt`): each subpath tracks its
//! medium through null boundaries (core's `RayWalk`), samples free-flight distances (one-sample
//! spectral MIS over the channels of each event, `FreeFlight::weight`), and scattering events
//! in a medium are vertices like surface ones (the phase function as their BSDF, a cosine of
//! one in the densities); every connection, next-event shadow ray and connection to the camera
//! carries the transmittance of the media and null boundaries it crosses
//! (`Scene::transmittance`). The densities of the MIS weights leave out the free-flight
//! probabilities (as pbrt-v3's do): the weights of a path's strategies still sum to one.
//! An emitting medium is found by the camera subpath alone (s = 0 at each scattering event
//! in it, weight 1: no light subpath starts in a medium). Light tracing alone (`strategy =
//! "light"` or `"s,1"`) has infinite variance in a medium
//! around the pinhole (a vertex at distance d contributes as 1 / d^2); the full estimator
//! weights it away there.
//!
//! `hide_emitters` (Mitsuba's, as `path` renders it): camera rays pass through emitters until
//! they first scatter, so the s = 0, t = 2 strategy never meets one; the light's own point is
//! not splatted (s = 1, t = 1), and a light vertex's connection to the camera (t = 1) passes
//! through emitters as the camera ray would and is not made from a point on an emitter (the
//! camera sees through those). Refused with participating media (that connection would have to
//! carry the media's transmittance past the emitters).
//!
//! `foton render --techniques` keeps each strategy's MIS-weighted share of the image as a layer
//! named `s<s>t<t>` (the t = 1 ones from their splats), for the strategies of path length
//! k = s + t - 1 (edges, Veach's convention: 1 is an emitter seen directly, 2 direct lighting)
//! up to `--techniques-depth` N (default 5), and the longer ones pooled in one layer, `rest`
//! (present when `max_depth + 1 > N`): Veach's pyramid of strategies, row k holding
//! s = 0 ... k.
//!
//! The subpaths, the connections and their MIS quantities live in `foton-bidir`
//! (integrators/bidir), which `vcm` shares: this crate reads the parameters and runs core's
//! splatting pixel loop, one light subpath per camera sample.

pub use foton_bidir::{Strategy, mis};

use foton_bidir::{Bidir, SplatSink};
use foton_core::api::{
    Error, Film, Integrator, Parameter, Properties, RenderContext, Result, Rgb, Scene, Splats,
    Techniques, render_pixels_splatting, render_pixels_techniques,
};

/// The plugin: foton-bidir's estimator with merging off, one light subpath per camera sample.
pub struct Bdpt(pub Bidir);

impl Bdpt {
    /// The longest path length (s + t - 1) with a layer of its own under `--techniques-depth
    /// depth`: no more than the longest path rendered (`max_depth + 1`).
    fn layered_length(&self, depth: u32) -> u32 {
        depth.min(self.0.max_depth.saturating_add(1))
    }
}

/// The layer of strategy (s, t) when paths up to length `layered` have a layer per strategy:
/// row k = s + t - 1 of the pyramid starts after the k - 1 rows above it (2 + 3 + ... + k
/// strategies), and the longer paths share the layer after the last row (`rest`).
#[inline]
pub fn strategy_layer(s: u32, t: u32, layered: u32) -> usize {
    let k = s + t - 1;
    let row = k.min(layered + 1);
    let start = (row as usize - 1) * (row as usize + 2) / 2;
    if k <= layered {
        start + s as usize
    } else {
        start
    }
}

/// Where `--techniques` sends bdpt's contributions: every splat to the film's splats and its
/// strategy's layer, every share of a camera sample to its strategy's layer.
struct StrategyLayers<'a, 'b, 'c> {
    splats: &'a mut Splats<'b>,
    techniques: &'a mut Techniques<'c>,
    layered: u32,
    /// The last layer: `rest`, or without it the last strategy of row `layered` (where the
    /// strategies past `max_depth`, all of weight zero, are sent).
    last: usize,
}

impl StrategyLayers<'_, '_, '_> {
    #[inline]
    fn layer(&self, s: u32, t: u32) -> usize {
        strategy_layer(s, t, self.layered).min(self.last)
    }
}

impl SplatSink for StrategyLayers<'_, '_, '_> {
    const SHARES: bool = true;

    fn add(&mut self, x: u32, y: u32, value: Rgb, weight: f32) {
        // Every splat of the estimator comes with its strategy (add_strategy).
        self.splats.add_weighted(x, y, value, weight);
    }

    fn add_strategy(&mut self, s: u32, x: u32, y: u32, value: Rgb, weight: f32) {
        self.splats.add_weighted(x, y, value, weight);
        let k = self.layer(s, 1);
        self.techniques.splat_weighted(k, x, y, value, weight);
    }

    fn share(&mut self, s: u32, t: u32, value: Rgb) {
        self.techniques.add(self.layer(s, t), value);
    }
}

impl Integrator for Bdpt {
    fn render(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Film> {
        let light_media = scene.emission_media()?;
        let Some(depth) = ctx.techniques else {
            return render_pixels_splatting(scene, ctx, |ps, sampler, splats, rays| {
                self.0
                    .sample(scene, &light_media, ps, sampler, splats, rays)
            });
        };
        let layered = self.layered_length(depth);
        let names = self.techniques(depth);
        render_pixels_techniques(
            scene,
            ctx,
            &names,
            |ps, sampler, splats, techniques, rays| {
                let mut layers = StrategyLayers {
                    splats,
                    techniques,
                    layered,
                    last: names.len() - 1,
                };
                self.0
                    .sample(scene, &light_media, ps, sampler, &mut layers, rays)
            },
        )
    }

    /// `s<s>t<t>` for each strategy of path length s + t - 1 up to `depth`, row by row (s = 0
    /// first), then `rest` if longer paths are rendered.
    fn techniques(&self, depth: u32) -> Vec<String> {
        let layered = self.layered_length(depth);
        let mut names = Vec::new();
        for k in 1..=layered {
            for s in 0..=k {
                names.push(format!("s{s}t{}", k + 1 - s));
            }
        }
        if self.0.max_depth.saturating_add(1) > layered {
            names.push("rest".into());
        }
        names
    }

    fn name(&self) -> &str {
        "bdpt"
    }

    fn parameters(&self) -> Vec<Parameter> {
        vec![
            Parameter::int("rr_depth", self.0.rr_depth),
            Parameter::bool("light_image", self.0.light_image),
            Parameter::str("strategy", self.0.strategy.name()),
        ]
    }
}

/// Reads the parameters (see the table above).
pub fn create(props: &Properties<'_>, scene: &Scene) -> Result<Box<dyn Integrator>> {
    let rr_depth = props.u32("rr_depth", 5)?;
    let light_image = props.bool("light_image", true)?;
    let strategy = Strategy::parse(props.string("strategy", "all")?)
        .map_err(|e| props.error("strategy", e))?;
    if scene.render().hide_emitters && scene.has_media() {
        return Err(Error::Usage(format!(
            "{}: `bdpt` does not render hide_emitters in a scene with participating media \
             (a light path connected to the camera would have to pass emitters and media as a \
             camera ray does): use `path`",
            scene.file().display()
        )));
    }
    Ok(Box::new(Bdpt(Bidir::new(
        scene.render().max_depth,
        rr_depth,
        strategy,
        light_image,
    ))))
}

foton_core::api::declare_integrator!("bdpt", "bidirectional path tracer (Veach, MIS)", create);
