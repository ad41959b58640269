//! `independent`: independent uniform numbers, one PCG stream per camera sample (pbrt-v4's
//! `IndependentSampler`). No parameters.

use super::rng::Rng;
use super::sampler::{SampleStart, SamplerFactory, SamplerImpl};
use glam::Vec2;

/// The settings of `independent` (none).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Independent;

/// The numbers of `Rng::new(&[seed, pixel, index])` (or of the integrator's keys).
#[derive(Clone, Debug)]
pub struct IndependentSampler {
    rng: Rng,
}

impl SamplerImpl for IndependentSampler {
    type Settings = Independent;
    // No pattern, so nothing to decorrelate between pixels.
    const USES_PIXEL_KEY: bool = false;

    #[inline]
    fn start(_: Independent, sample: SampleStart) -> Self {
        IndependentSampler { rng: sample.rng }
    }
    #[inline]
    fn next_f32(&mut self) -> f32 {
        self.rng.next_f32()
    }
    #[inline]
    fn next_2d(&mut self) -> Vec2 {
        self.rng.next_2d()
    }
}

pub const FACTORY: SamplerFactory<IndependentSampler> = SamplerFactory {
    name: "independent",
    description: "independent uniform numbers, one random stream per camera sample",
    create: |_| Ok(Independent),
};
