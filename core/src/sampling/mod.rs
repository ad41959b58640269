//! Sampling, a file a concept (as pbrt-v4's `util/rng.h`, `samplers.h`, `util/lowdiscrepancy.h`
//! and `util/sampling.h`): random numbers (`rng.rs`), the samplers integrators draw from
//! (`sampler.rs`, the interface and the dispatch, and one file per kind: `independent.rs`,
//! `stratified.rs`, `sobol.rs`, listed in [`SAMPLERS`]), Owen-scrambled Sobol points
//! (`lowdiscrepancy.rs`), the warps that turn numbers into directions and points (`warp.rs`),
//! tabulated distributions (`distribution.rs`); here, the two rules every path integrator
//! applies (Russian roulette, the power heuristic), and every item of the files, re-exported:
//! `sampling::Rng` is the path to use.
//!
//! Every camera sample owns its own stream, keyed by (seed, pixel, sample index), so an image
//! is bit-identical whatever the number of threads or the order in which tiles run.

mod distribution;
mod lowdiscrepancy;
mod rng;
mod sampler;
mod warp;

sampler::samplers! {
    /// The built-in samplers, one line each (a file in `sampling/` whose sampler implements
    /// [`SamplerImpl`] and which ends with its `FACTORY`): what `[render] sampler` names.
    pub const SAMPLERS = [
        independent::IndependentSampler,
        stratified::StratifiedSampler,
        sobol::SobolSampler,
    ];
}

pub use distribution::{Distribution1D, Distribution2D};
pub use lowdiscrepancy::{
    SOBOL_BLOCK, SOBOL_DIMENSIONS, SobolBlock, SobolPoint, owen_scramble, shuffled_index,
    sobol_block, sobol_dimension, unit_f32,
};
pub use rng::{ONE_MINUS_EPSILON, Rng, hash32, splitmix64};
pub use sampler::{PixelSamplers, SampleStart, Sampler, SamplerFactory, SamplerImpl, SamplerKind};
pub use stratified::{permutation_element, strata_2d};
pub use warp::{
    UNIFORM_SPHERE_PDF, basis, concentric_disc, cosine_hemisphere, to_world, uniform_cone,
    uniform_hemisphere, uniform_sphere, uniform_triangle,
};

/// Russian roulette past `rr_depth` scattering events (the path tracer's rule, shared by every
/// integrator that walks paths): survives with probability max(beta) (at most 0.95) and
/// divides the throughput by it, which keeps its expectation and ends dim paths. False if the
/// path ends; draws one number only past `rr_depth`.
#[inline]
pub fn russian_roulette(
    depth: u32,
    rr_depth: u32,
    beta: &mut crate::Rgb,
    sampler: &mut Sampler,
) -> bool {
    if depth < rr_depth {
        return true;
    }
    let survive = beta.max_element().min(0.95);
    if survive <= 0.0 || sampler.next_f32() >= survive {
        return false;
    }
    *beta /= survive;
    true
}

/// Veach's power heuristic with beta = 2 (one sample from each strategy).
#[inline]
pub fn power_heuristic(pdf_f: f32, pdf_g: f32) -> f32 {
    let f = pdf_f * pdf_f;
    let g = pdf_g * pdf_g;
    if f.is_infinite() {
        return 1.0;
    }
    if f + g == 0.0 { 0.0 } else { f / (f + g) }
}
