//! The [`Sampler`] every integrator draws from, and the kinds it comes in (pbrt-v4's
//! `IndependentSampler`, `StratifiedSampler` and a padded, Owen-scrambled `SobolSampler`).

use super::rng::{ONE_MINUS_EPSILON, RNG_KEYS_START, Rng, hash_keys, splitmix64};
use super::sobol::{SOBOL_BLOCK, SobolBlock, sobol_block};
use glam::Vec2;

/// Which points a [`Sampler`] hands out (`[render] sampler`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SamplerKind {
    /// Independent uniform numbers: one PCG stream per camera sample.
    #[default]
    Independent,
    /// Per-dimension strata, one per sample of the pixel, randomly permuted per dimension
    /// (pbrt's `StratifiedSampler`); `jitter = false` takes each stratum's centre.
    Stratified { jitter: bool },
    /// Owen-scrambled Sobol points (Burley 2020), padded: every 1-D or 2-D request takes the
    /// first two Sobol dimensions with its own index shuffle and scramble. The least error at
    /// equal time on every scene measured, and the TOML scenes' default (docs/PERFORMANCE.md).
    Sobol,
}

impl SamplerKind {
    /// The names `[render] sampler` takes.
    pub const NAMES: [&'static str; 3] = ["independent", "stratified", "sobol"];

    /// The sampler named `name`; `jitter` applies to `stratified` only.
    pub fn from_name(name: &str, jitter: bool) -> Option<SamplerKind> {
        match name {
            "independent" => Some(SamplerKind::Independent),
            "stratified" => Some(SamplerKind::Stratified { jitter }),
            "sobol" => Some(SamplerKind::Sobol),
            _ => None,
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            SamplerKind::Independent => "independent",
            SamplerKind::Stratified { .. } => "stratified",
            SamplerKind::Sobol => "sobol",
        }
    }
}

/// The numbers one camera sample draws, dimension after dimension (pbrt-v4's `Sampler`:
/// `StartPixelSample`, then `Get1D` / `Get2D` in a fixed order). The first 2-D request is
/// the position on the film. Integrators call [`Sampler::next_f32`] and [`Sampler::next_2d`];
/// which points come back depends on the kind, and on (seed, pixel, sample index) alone, so an
/// image is the same for any thread count and any split into parts.
///
/// A concrete enum rather than a trait object: the sampler is in the innermost loop, and the
/// branch on the kind is the same for a whole render, so it predicts perfectly.
#[derive(Clone, Debug)]
pub struct Sampler {
    kind: SamplerKind,
    /// `kind` without its payload, for the requests' one test (see [`Request`]).
    request: Request,
    /// The independent stream; for `stratified`, the jitter inside strata.
    rng: Rng,
    /// Hash of (seed, pixel): what decorrelates the patterns of neighbouring pixels.
    pub(super) pixel_key: u64,
    /// The sample's index within its pixel.
    index: u32,
    /// `index` with its bits reversed (`sobol` only; see [`sobol_block`]).
    index_reversed: u32,
    /// Samples the pixel takes in all (strata per dimension).
    spp: u32,
    /// The next dimension to hand out (`stratified`; `sobol` counts in blocks).
    dimension: u32,
    /// `sobol`: the points of dimensions `block_start..block_start + SOBOL_BLOCK`, computed
    /// together ([`sobol_block`]); before the first block, `0 - SOBOL_BLOCK` (the first block
    /// starts `SOBOL_BLOCK` past it).
    block_start: u32,
    /// `sobol`: the place in `block` of the next dimension to hand out (`SOBOL_BLOCK`: the
    /// next block is to be computed). Requests come in order, so the next dimension is
    /// `block_start + block_pos`: one counter moved on per request.
    block_pos: u32,
    block: SobolBlock,
}

impl Sampler {
    /// Sample `index` of `spp` of `pixel` (any number that names the pixel, e.g. y width + x).
    /// With `Independent` the numbers are those of `Rng::new(&[seed, pixel, index])`.
    /// (A loop over the samples of one pixel makes them with [`PixelSamplers`], which hashes
    /// the seed and the pixel once.)
    #[inline]
    pub fn new(kind: SamplerKind, seed: u64, pixel: u64, index: u32, spp: u32) -> Sampler {
        PixelSamplers::new(kind, seed, pixel, spp).sample(index)
    }

    /// As [`Sampler::new`], with the independent stream keyed by `keys` (integrators that
    /// separate their streams with an extra key, as `sppm`'s camera pass does).
    // Inlined so that the hash over the keys unrolls for the caller's fixed number of keys.
    #[inline]
    pub fn with_keys(
        kind: SamplerKind,
        keys: &[u64],
        seed: u64,
        pixel: u64,
        index: u32,
        spp: u32,
    ) -> Sampler {
        let rng = if kind == SamplerKind::Sobol {
            Rng::UNUSED
        } else {
            Rng::new(keys)
        };
        Sampler::from_parts(kind, rng, pixel_key(kind, seed, pixel), index, spp)
    }

    /// The sampler of sample `index` with its stream and pixel key made.
    #[inline]
    fn from_parts(kind: SamplerKind, rng: Rng, pixel_key: u64, index: u32, spp: u32) -> Sampler {
        Sampler {
            kind,
            request: match kind {
                SamplerKind::Independent => Request::Independent,
                SamplerKind::Sobol => Request::Sobol,
                SamplerKind::Stratified { .. } => Request::Stratified,
            },
            rng,
            pixel_key,
            index,
            index_reversed: index.reverse_bits(),
            spp: spp.max(1),
            dimension: 0,
            block_start: 0u32.wrapping_sub(SOBOL_BLOCK as u32),
            block_pos: SOBOL_BLOCK as u32,
            block: SobolBlock::EMPTY,
        }
    }

    pub fn kind(&self) -> SamplerKind {
        self.kind
    }

    /// Uniform in [0, 1).
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        // Independent first, by one byte compare (see [`Request`]).
        if self.request == Request::Independent {
            self.rng.next_f32()
        } else if self.request == Request::Sobol {
            // Two loads while the block lasts, inlined like the independent stream's draw.
            self.sobol_point().0
        } else {
            self.next_1d_stratified()
        }
    }

    /// Uniform in [0, 1)^2; the two coordinates are stratified together.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        if self.request == Request::Independent {
            self.rng.next_2d()
        } else if self.request == Request::Sobol {
            let (x, y) = self.sobol_point();
            Vec2::new(x, y)
        } else {
            self.next_2d_stratified()
        }
    }

    /// Hash of (pixel, dimension), and the dimension counter moved on.
    #[inline]
    fn dimension_key(&mut self) -> u64 {
        let d = self.dimension;
        self.dimension += 1;
        dimension_key(self.pixel_key, d)
    }

    /// Index within the pixel's strata, and a key for the round when the index is past spp
    /// (sppm's iterations without a bound): each round is a new random permutation.
    #[inline]
    fn stratum_index(&self, key: u64) -> (u32, u32) {
        let round = (self.index / self.spp) as u64;
        let key = if round == 0 {
            key
        } else {
            splitmix64(key ^ round)
        };
        let p = permutation_element(self.index % self.spp, self.spp, key as u32);
        (p, (key >> 32) as u32)
    }

    /// The next dimension's Sobol point (both coordinates; a 1-D request takes the first,
    /// which is what it would compute alone), from the block of [`SOBOL_BLOCK`] dimensions
    /// that holds it, computed when the block's first dimension is asked for.
    #[inline(always)]
    fn sobol_point(&mut self) -> (f32, f32) {
        let mut k = self.block_pos;
        if k >= SOBOL_BLOCK as u32 {
            self.next_sobol_block();
            k = 0;
        }
        self.block_pos = k + 1;
        (self.block.x[k as usize], self.block.y[k as usize])
    }

    /// Computes the block after the current one (the first block, before any).
    #[inline(never)]
    fn next_sobol_block(&mut self) {
        self.block_start = self.block_start.wrapping_add(SOBOL_BLOCK as u32);
        sobol_block(
            self.pixel_key,
            self.index_reversed,
            self.block_start,
            &mut self.block,
        );
    }

    fn next_1d_stratified(&mut self) -> f32 {
        let SamplerKind::Stratified { jitter } = self.kind else {
            unreachable!("called for the stratified sampler only")
        };
        let key = self.dimension_key();
        let (stratum, _) = self.stratum_index(key);
        let offset = if jitter { self.rng.next_f32() } else { 0.5 };
        ((stratum as f32 + offset) / self.spp as f32).min(ONE_MINUS_EPSILON)
    }

    fn next_2d_stratified(&mut self) -> Vec2 {
        let SamplerKind::Stratified { jitter } = self.kind else {
            unreachable!("called for the stratified sampler only")
        };
        let key = self.dimension_key();
        let (stratum, _) = self.stratum_index(key);
        let (nx, ny) = strata_2d(self.spp);
        let (sx, sy) = (stratum % nx, stratum / nx);
        let (jx, jy) = if jitter {
            (self.rng.next_f32(), self.rng.next_f32())
        } else {
            (0.5, 0.5)
        };
        Vec2::new(
            ((sx as f32 + jx) / nx as f32).min(ONE_MINUS_EPSILON),
            ((sy as f32 + jy) / ny as f32).min(ONE_MINUS_EPSILON),
        )
    }
}

/// A sampler's pixel key: the hash of (seed, pixel) that decorrelates the patterns of
/// neighbouring pixels. Not needed by the independent stream, whose samples should cost what
/// they did.
#[inline]
fn pixel_key(kind: SamplerKind, seed: u64, pixel: u64) -> u64 {
    if kind == SamplerKind::Independent {
        0
    } else {
        splitmix64(splitmix64(seed ^ 0x5A3F_C0DE) ^ pixel)
    }
}

/// What the samplers of one pixel share: the hashes of the seed and the pixel (the pixel key,
/// and the independent stream's keys before the sample index), made once for all the pixel's
/// samples. [`PixelSamplers::sample`] gives the sampler [`Sampler::new`] gives.
#[derive(Clone, Copy, Debug)]
pub struct PixelSamplers {
    kind: SamplerKind,
    /// `Rng::new`'s hash of (seed, pixel), before the sample index (not for `sobol`).
    keys_hash: u64,
    pixel_key: u64,
    spp: u32,
}

impl PixelSamplers {
    /// The samplers of `pixel` (as in [`Sampler::new`]).
    #[inline]
    pub fn new(kind: SamplerKind, seed: u64, pixel: u64, spp: u32) -> PixelSamplers {
        PixelSamplers {
            kind,
            keys_hash: if kind == SamplerKind::Sobol {
                0
            } else {
                hash_keys(RNG_KEYS_START, &[seed, pixel])
            },
            pixel_key: pixel_key(kind, seed, pixel),
            spp,
        }
    }

    /// The sampler of the pixel's sample `index`: `Sampler::new(kind, seed, pixel, index, spp)`.
    #[inline]
    pub fn sample(&self, index: u32) -> Sampler {
        let rng = if self.kind == SamplerKind::Sobol {
            Rng::UNUSED
        } else {
            Rng::from_hash(hash_keys(self.keys_hash, &[index as u64]))
        };
        Sampler::from_parts(self.kind, rng, self.pixel_key, index, self.spp)
    }
}

/// How a [`Sampler`]'s requests are answered: [`SamplerKind`] without `stratified`'s payload.
/// `SamplerKind` keeps its `jitter` in the byte that tells the kinds apart, so a `match` on it
/// in every request compiled to a chain of compares (about 7 instructions a request on the
/// Cornell box, against 2 when only the independent arm was inline: `independent` renders
/// lost 3 to 4 %); a plain byte tested for `Independent` first is one compare and a branch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
enum Request {
    Independent,
    Sobol,
    Stratified,
}

/// The hash of (pixel, dimension) that seeds a `stratified` dimension's permutation.
#[inline(always)]
fn dimension_key(pixel_key: u64, dimension: u32) -> u64 {
    splitmix64(pixel_key ^ (dimension as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15))
}

/// The 2-D strata of `spp` samples: nx x ny = spp with nx the largest divisor of spp not above
/// its square root (a prime spp gives 1 x spp bands: stratified in y alone).
pub fn strata_2d(spp: u32) -> (u32, u32) {
    let mut nx = (spp as f64).sqrt() as u32;
    while nx > 1 && !spp.is_multiple_of(nx) {
        nx -= 1;
    }
    let nx = nx.max(1);
    (nx, spp / nx)
}

/// Element `i` of a random permutation of 0..n chosen by `seed` (Kensler 2013, "Correlated
/// multi-jittered sampling": a hash that is a bijection on the next power of two, walked until
/// it lands below n).
pub fn permutation_element(mut i: u32, n: u32, seed: u32) -> u32 {
    if n <= 1 {
        return 0;
    }
    let mut w = n - 1;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    let p = seed;
    loop {
        i ^= p;
        i = i.wrapping_mul(0xe170_893d);
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= p >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | p >> 27);
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= w;
        i ^= i >> 5;
        if i < n {
            break;
        }
    }
    (i.wrapping_add(p)) % n
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pixel's samplers made once per pixel draw what each sample's sampler keyed by
    /// (seed, pixel, index) draws, for every kind.
    #[test]
    fn pixel_samplers_draw_what_keyed_samplers_draw() {
        for kind in [
            SamplerKind::Independent,
            SamplerKind::Stratified { jitter: true },
            SamplerKind::Stratified { jitter: false },
            SamplerKind::Sobol,
        ] {
            for (seed, pixel) in [(0u64, 0u64), (7, 12345), (u64::MAX, 65535)] {
                let pixel_samplers = PixelSamplers::new(kind, seed, pixel, 16);
                for index in [0u32, 1, 5, 15, 16, 40] {
                    let keys = [seed, pixel, index as u64];
                    let mut a = pixel_samplers.sample(index);
                    let mut b = Sampler::with_keys(kind, &keys, seed, pixel, index, 16);
                    for d in 0..40 {
                        if d % 3 == 0 {
                            assert_eq!(a.next_2d(), b.next_2d(), "{kind:?} {index} {d}");
                        } else {
                            assert_eq!(a.next_f32(), b.next_f32(), "{kind:?} {index} {d}");
                        }
                    }
                }
            }
        }
    }
}
