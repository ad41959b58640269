//! `sobol`: Owen-scrambled Sobol points (Burley 2020), padded: every 1-D or 2-D request takes
//! the first two Sobol dimensions with its own index shuffle and scramble (pbrt-v4's
//! `PaddedSobolSampler`). The least error at equal time on every scene measured, and the TOML
//! scenes' default (docs/PERFORMANCE.md). No parameters. The points are computed in blocks of
//! [`SOBOL_BLOCK`] dimensions by [`sobol_block`] (`lowdiscrepancy.rs`).

use super::lowdiscrepancy::{SOBOL_BLOCK, SobolBlock, sobol_block};
use super::sampler::{SampleStart, SamplerFactory, SamplerImpl};
use glam::Vec2;

/// The settings of `sobol` (none).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sobol;

#[derive(Clone, Debug)]
pub struct SobolSampler {
    /// Hash of (seed, pixel): every dimension's shuffle and scramble are seeded by it.
    pub(super) pixel_key: u64,
    /// The sample's index with its bits reversed (see [`sobol_block`]).
    index_reversed: u32,
    /// The points of dimensions `block_start..block_start + SOBOL_BLOCK`, computed together;
    /// before the first block, `0 - SOBOL_BLOCK` (the first block starts `SOBOL_BLOCK` past
    /// it).
    block_start: u32,
    /// The place in `block` of the next dimension to hand out (`SOBOL_BLOCK`: the next block
    /// is to be computed). Requests come in order, so the next dimension is `block_start +
    /// block_pos`: one counter moved on per request.
    block_pos: u32,
    block: SobolBlock,
}

impl SobolSampler {
    /// The next dimension's Sobol point (both coordinates; a 1-D request takes the first,
    /// which is what it would compute alone), from the block of [`SOBOL_BLOCK`] dimensions
    /// that holds it, computed when the block's first dimension is asked for.
    #[inline(always)]
    fn point(&mut self) -> (f32, f32) {
        let mut k = self.block_pos;
        if k >= SOBOL_BLOCK as u32 {
            self.next_block();
            k = 0;
        }
        self.block_pos = k + 1;
        (self.block.x[k as usize], self.block.y[k as usize])
    }

    /// Computes the block after the current one (the first block, before any).
    #[inline(never)]
    fn next_block(&mut self) {
        self.block_start = self.block_start.wrapping_add(SOBOL_BLOCK as u32);
        sobol_block(
            self.pixel_key,
            self.index_reversed,
            self.block_start,
            &mut self.block,
        );
    }
}

impl SamplerImpl for SobolSampler {
    type Settings = Sobol;
    // The points are hashes of the pixel key and the sample index alone.
    const USES_RNG: bool = false;

    #[inline]
    fn start(_: Sobol, sample: SampleStart) -> Self {
        SobolSampler {
            pixel_key: sample.pixel_key,
            index_reversed: sample.index.reverse_bits(),
            block_start: 0u32.wrapping_sub(SOBOL_BLOCK as u32),
            block_pos: SOBOL_BLOCK as u32,
            block: SobolBlock::EMPTY,
        }
    }
    /// Two loads while the block lasts, inlined like the independent stream's draw.
    #[inline]
    fn next_f32(&mut self) -> f32 {
        self.point().0
    }
    #[inline]
    fn next_2d(&mut self) -> Vec2 {
        let (x, y) = self.point();
        Vec2::new(x, y)
    }
}

pub const FACTORY: SamplerFactory<SobolSampler> = SamplerFactory {
    name: "sobol",
    description: "Owen-scrambled Sobol points, padded (Burley 2020)",
    create: |_| Ok(Sobol),
};
