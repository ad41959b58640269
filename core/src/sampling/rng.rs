//! Random numbers: the integer hashes that key them, and PCG32 streams.
//!
//! Every camera sample owns its own stream, keyed by (seed, pixel, sample index), so an image
//! is bit-identical whatever the number of threads or the order in which tiles run.

use glam::Vec2;

#[inline]
pub fn splitmix64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// The largest f32 below 1.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// PCG32 (O'Neill): small, fast and statistically good.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
    inc: u64,
}

/// The hash [`Rng::new`] starts its keys from.
pub(super) const RNG_KEYS_START: u64 = 0x2545_F491_4F6C_DD1D;

/// The hash of `keys` after `h` (what [`Rng::new`] hashes its keys with, from
/// [`RNG_KEYS_START`]): keys hashed in two parts give the hash of them all.
#[inline]
pub(super) fn hash_keys(mut h: u64, keys: &[u64]) -> u64 {
    for &k in keys {
        h = splitmix64(h ^ k);
    }
    h
}

impl Rng {
    /// A stream determined by a tuple of keys, e.g. (seed, pixel, sample).
    #[inline]
    pub fn new(keys: &[u64]) -> Self {
        Rng::from_hash(hash_keys(RNG_KEYS_START, keys))
    }

    /// A stream that is never drawn from (a `sobol` sampler's: its points are hashes of the
    /// pixel key and the sample index alone).
    pub(super) const UNUSED: Rng = Rng { state: 0, inc: 1 };

    /// The stream of the keys whose hash is `h` ([`hash_keys`]).
    #[inline]
    pub(super) fn from_hash(h: u64) -> Self {
        let mut rng = Rng {
            state: 0,
            inc: (splitmix64(h ^ 0xDA3E_39CB_94B9_5BDB) << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(h);
        rng.next_u32();
        rng
    }

    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in [0, 1).
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        Vec2::new(self.next_f32(), self.next_f32())
    }
}

/// Wellons' `lowbias32` (github.com/skeeto/hash-prospector): a 32-bit integer hash, a
/// bijection with low avalanche bias, two multiplies.
#[inline(always)]
pub fn hash32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^ (x >> 16)
}
