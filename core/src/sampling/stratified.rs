//! `stratified`: per-dimension strata, one per sample of the pixel, randomly permuted per
//! dimension (pbrt-v4's `StratifiedSampler`): every dimension of a pixel's `spp` samples hits
//! each of its strata once (2-D requests: an nx x ny grid, [`strata_2d`]); past `spp` samples
//! (sppm's iterations without a bound) each round of `spp` is a new permutation.
//!
//! | Parameter | Type    | Meaning                                                   | Default |
//! |-----------|---------|-----------------------------------------------------------|---------|
//! | `jitter`  | boolean | a random point in each stratum; `false`: its centre        | `true`  |

use super::rng::{ONE_MINUS_EPSILON, Rng, splitmix64};
use super::sampler::{SampleStart, SamplerFactory, SamplerImpl};
use glam::Vec2;

/// The settings of `stratified`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stratified {
    /// A random point in each stratum; false: its centre.
    pub jitter: bool,
}

#[derive(Clone, Debug)]
pub struct StratifiedSampler {
    jitter: bool,
    /// The jitter inside strata.
    rng: Rng,
    /// Hash of (seed, pixel): what decorrelates the permutations of neighbouring pixels.
    pixel_key: u64,
    /// The sample's index within its pixel.
    index: u32,
    /// Samples the pixel takes in all (strata per dimension).
    spp: u32,
    /// The next dimension to hand out.
    dimension: u32,
}

impl StratifiedSampler {
    /// Hash of (pixel, dimension), and the dimension counter moved on.
    #[inline]
    fn dimension_key(&mut self) -> u64 {
        let d = self.dimension;
        self.dimension += 1;
        splitmix64(self.pixel_key ^ (d as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15))
    }

    /// Index within the pixel's strata, and a key for the round when the index is past spp:
    /// each round is a new random permutation.
    #[inline]
    fn stratum_index(&self, key: u64) -> u32 {
        let round = (self.index / self.spp) as u64;
        let key = if round == 0 {
            key
        } else {
            splitmix64(key ^ round)
        };
        permutation_element(self.index % self.spp, self.spp, key as u32)
    }
}

impl SamplerImpl for StratifiedSampler {
    type Settings = Stratified;

    #[inline]
    fn start(settings: Stratified, sample: SampleStart) -> Self {
        StratifiedSampler {
            jitter: settings.jitter,
            rng: sample.rng,
            pixel_key: sample.pixel_key,
            index: sample.index,
            spp: sample.spp,
            dimension: 0,
        }
    }

    fn next_f32(&mut self) -> f32 {
        let key = self.dimension_key();
        let stratum = self.stratum_index(key);
        let offset = if self.jitter {
            self.rng.next_f32()
        } else {
            0.5
        };
        ((stratum as f32 + offset) / self.spp as f32).min(ONE_MINUS_EPSILON)
    }

    fn next_2d(&mut self) -> Vec2 {
        let key = self.dimension_key();
        let stratum = self.stratum_index(key);
        let (nx, ny) = strata_2d(self.spp);
        let (sx, sy) = (stratum % nx, stratum / nx);
        let (jx, jy) = if self.jitter {
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

pub const FACTORY: SamplerFactory<StratifiedSampler> = SamplerFactory {
    name: "stratified",
    description: "one stratum per sample in every dimension, randomly permuted (pbrt's)",
    create: |render| {
        Ok(Stratified {
            jitter: render.bool("jitter", true)?,
        })
    },
};
