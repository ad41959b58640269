//! Random numbers and the warps that turn them into directions and points.
//!
//! Every camera sample owns its own stream, keyed by (seed, pixel, sample index), so an image
//! is bit-identical whatever the number of threads or the order in which tiles run.

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[inline]
pub fn splitmix64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// PCG32 (O'Neill): small, fast and statistically good.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
    inc: u64,
}

/// The hash [`Rng::new`] starts its keys from.
const RNG_KEYS_START: u64 = 0x2545_F491_4F6C_DD1D;

/// The hash of `keys` after `h` (what [`Rng::new`] hashes its keys with, from
/// [`RNG_KEYS_START`]): keys hashed in two parts give the hash of them all.
#[inline]
fn hash_keys(mut h: u64, keys: &[u64]) -> u64 {
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
    const UNUSED: Rng = Rng { state: 0, inc: 1 };

    /// The stream of the keys whose hash is `h` ([`hash_keys`]).
    #[inline]
    fn from_hash(h: u64) -> Self {
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
    pixel_key: u64,
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

/// Dimensions of a `sobol` sampler computed together ([`sobol_block`]).
pub const SOBOL_BLOCK: usize = 8;

/// The points of [`SOBOL_BLOCK`] consecutive dimensions of one `sobol` sample: `x` is a 1-D
/// request's value and a 2-D request's first coordinate, `y` the second.
#[derive(Clone, Copy, Debug)]
pub struct SobolBlock {
    pub x: [f32; SOBOL_BLOCK],
    pub y: [f32; SOBOL_BLOCK],
}

impl SobolBlock {
    const EMPTY: SobolBlock = SobolBlock {
        x: [0.0; SOBOL_BLOCK],
        y: [0.0; SOBOL_BLOCK],
    };
}

/// The Owen-scrambled Sobol points of dimensions `first..first + SOBOL_BLOCK` of the sample
/// whose pixel key and reversed index are given (the [`Sampler`]'s fields), into `block`.
///
/// Padding (Burley 2020, section 4): every dimension takes Sobol dimensions 0 and 1, a
/// (0, 2)-sequence, with its own shuffle of the sample index, so dimensions are independent
/// of one another and each is as well stratified as the first. Two 32-bit hashes give the
/// three 32-bit seeds ([`sobol_seeds`]). The point is `owen_scramble(sobol_dimension(i, d), s)` of
/// the shuffled index i, with the bit reversals that cancel left out:
///
/// * the shuffle is [`shuffled_index`] of the index, whose two scrambles share their outer
///   bit reversal (it is linear over xor): one reversal of the reversed index's hash, where
///   there were four. Only the low 24 bits of the shuffled index matter: a point keeps the
///   top 24 bits of its 32-bit fraction ([`unit_f32`]), which are the low 24 of what the
///   scramble hashes (bit-reversed), and each bit of the hash depends only on the bits below
///   it; the Sobol matrices' reversed columns past 23 have no bits below 24;
/// * dimension 0 reverses the index's bits and the scramble reverses them back before
///   hashing; dimension 1 is its reversed matrix's product with the index in five
///   shift-mask-xor steps ([`sobol_1_reversed`]).
///
/// Eight dimensions are computed at once, each step for all of them, because that runs in
/// the eight 32-bit lanes of an AVX2 register where the processor has them (the hashes are
/// 32-bit multiplies and shifts, the bit reversals byte shuffles, dimension 1 five
/// shift-mask-xor steps): about 21 instructions a dimension (170 a block) with a 64-bit key
/// hash, against about 105 one at a time with a data-dependent loop (docs/PERFORMANCE.md,
/// sessions 26 to 28). Integer arithmetic,
/// so the points are the same bits with or without AVX2, and as one dimension alone computes
/// them (unit test `sobol_block_matches_each_lane`). A sample that ends inside a block has
/// computed a few dimensions it does not use (on the Cornell box, 21 for 17).
#[inline]
pub fn sobol_block(pixel_key: u64, index_reversed: u32, first: u32, block: &mut SobolBlock) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor has AVX2 (checked just above).
            return unsafe { sobol_block_avx2(pixel_key, index_reversed, first, block) };
        }
    }
    sobol_block_lanes(pixel_key, index_reversed, first, block)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn sobol_block_avx2(
    pixel_key: u64,
    index_reversed: u32,
    first: u32,
    block: &mut SobolBlock,
) {
    sobol_block_lanes(pixel_key, index_reversed, first, block)
}

/// [`sobol_block`] written step by step over arrays of lanes, for the compiler to vectorise.
#[inline(always)]
fn sobol_block_lanes(pixel_key: u64, index_reversed: u32, first: u32, block: &mut SobolBlock) {
    const N: usize = SOBOL_BLOCK;
    let (mut seed, mut sx, mut sy) = ([0u32; N], [0u32; N], [0u32; N]);
    for k in 0..N {
        (seed[k], sx[k], sy[k]) = sobol_seeds(pixel_key, first.wrapping_add(k as u32));
    }
    let mut i = [0u32; N];
    for k in 0..N {
        i[k] = reverse_24(laine_karras(index_reversed, seed[k]) ^ laine_karras(0, seed[k]));
    }
    for k in 0..N {
        block.x[k] = reversed_unit_f32(laine_karras(i[k], sx[k]));
    }
    for k in 0..N {
        block.y[k] = reversed_unit_f32(laine_karras(sobol_1_reversed(i[k]), sy[k]));
    }
}

/// The hash of (pixel, dimension) that seeds a `stratified` dimension's permutation.
#[inline(always)]
fn dimension_key(pixel_key: u64, dimension: u32) -> u64 {
    splitmix64(pixel_key ^ (dimension as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15))
}

/// The three 32-bit seeds of a `sobol` dimension (the index shuffle's, and the scrambles of
/// the point's two coordinates), from the pixel's key and the dimension: two 32-bit hashes,
/// the first of the key's low half and the dimension, the second of the first and the key's
/// high half; the third seed mixes the halves of both. 32-bit arithmetic because it runs in
/// AVX2's eight 32-bit lanes (a 64-bit `splitmix64` per dimension, as before session 28, has
/// no AVX2 multiply and was a third of a block's instructions). The seeds need to differ
/// from dimension to dimension and pixel to pixel and look random, not be independent bits:
/// for one pixel each hash is a bijection of the dimension, so no two dimensions share a
/// shuffle or a scramble.
#[inline(always)]
fn sobol_seeds(pixel_key: u64, dimension: u32) -> (u32, u32, u32) {
    let h1 = hash32(pixel_key as u32 ^ dimension.wrapping_mul(0x9E37_79B9));
    let h2 = hash32(h1 ^ (pixel_key >> 32) as u32);
    (h1, h2, ((h1 >> 16) | (h2 << 16)) ^ 0x9E37_79B9)
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

/// One dimension's point alone, both coordinates, as [`sobol_block`] computes eight: the
/// reference its unit test compares the blocks with.
#[cfg(test)]
fn sobol_lane(pixel_key: u64, dimension: u32, index_reversed: u32) -> (f32, f32) {
    let (seed, sx, sy) = sobol_seeds(pixel_key, dimension);
    let i = reverse_24(laine_karras(index_reversed, seed) ^ laine_karras(0, seed));
    (
        reversed_unit_f32(laine_karras(i, sx)),
        reversed_unit_f32(laine_karras(sobol_1_reversed(i), sy)),
    )
}

/// `sobol_dimension_reversed(i, 1)` without the data-dependent loop, in five steps. Sobol's
/// dimension 1 has direction numbers (1 + x)^k (primitive polynomial x + 1), so column k of
/// its matrix holds the binomial coefficients C(k, p) mod 2, and by Lucas' theorem C(k, p) is
/// odd exactly when the bits of p are a subset of those of k. Bit p of the reversed point is
/// then the xor of the index bits k whose positions are supersets of p (as 5-bit numbers): a
/// superset-sum over the five bits of a position, one shift, mask and xor per bit, for all 32
/// positions at once (branch-free, so it vectorises; 24 masked columns before).
#[inline(always)]
fn sobol_1_reversed(i: u32) -> u32 {
    let mut x = i;
    // Positions whose bit b is 0 take the sums of the positions with it set (p + 2^b).
    x ^= (x >> 1) & 0x5555_5555;
    x ^= (x >> 2) & 0x3333_3333;
    x ^= (x >> 4) & 0x0F0F_0F0F;
    x ^= (x >> 8) & 0x00FF_00FF;
    x ^= (x >> 16) & 0x0000_FFFF;
    x
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

/// The first Sobol dimensions' generator matrices as 32 direction numbers each, column k
/// for bit k of the index, the first bit of the result in the highest bit. Dimension 0 is
/// van der Corput's; the others follow from Joe and Kuo's primitive polynomials and initial
/// numbers (new-joe-kuo-6.21201: (s, a, m) = (1, 0, [1]), (2, 1, [1, 3]), (3, 1, [1, 3, 1]),
/// (3, 2, [1, 1, 1]), (4, 1, [1, 1, 3, 3])).
pub const SOBOL_DIMENSIONS: usize = 6;
static SOBOL_MATRICES: [[u32; 32]; SOBOL_DIMENSIONS] = {
    let params: [(u32, u32, [u32; 4]); SOBOL_DIMENSIONS - 1] = [
        (1, 0, [1, 0, 0, 0]),
        (2, 1, [1, 3, 0, 0]),
        (3, 1, [1, 3, 1, 0]),
        (3, 2, [1, 1, 1, 0]),
        (4, 1, [1, 1, 3, 3]),
    ];
    let mut m = [[0u32; 32]; SOBOL_DIMENSIONS];
    let mut k = 0;
    while k < 32 {
        m[0][k] = 1 << (31 - k);
        k += 1;
    }
    let mut d = 1;
    while d < SOBOL_DIMENSIONS {
        let (s, a, init) = params[d - 1];
        let s = s as usize;
        let mut k = 0;
        while k < 32 {
            m[d][k] = if k < s {
                init[k] << (31 - k)
            } else {
                let mut v = m[d][k - s] ^ (m[d][k - s] >> s);
                let mut j = 1;
                while j < s {
                    if (a >> (s - 1 - j)) & 1 == 1 {
                        v ^= m[d][k - j];
                    }
                    j += 1;
                }
                v
            };
            k += 1;
        }
        d += 1;
    }
    m
};

/// Sobol point `index` in `dimension` (< [`SOBOL_DIMENSIONS`]) as a 32-bit fraction.
#[inline]
pub fn sobol_dimension(mut index: u32, dimension: usize) -> u32 {
    if dimension == 0 {
        return index.reverse_bits();
    }
    let matrix = &SOBOL_MATRICES[dimension];
    let mut x = 0;
    while index != 0 {
        x ^= matrix[index.trailing_zeros() as usize];
        index &= index - 1;
    }
    x
}

/// The generator matrices with each column's bits reversed: by linearity over xor,
/// `sobol_dimension_reversed(i, d)` is `sobol_dimension(i, d).reverse_bits()`, which is what
/// Owen scrambling hashes, without reversing at run time (the tests' reference for
/// [`sobol_1_reversed`]).
#[cfg(test)]
static SOBOL_MATRICES_REVERSED: [[u32; 32]; SOBOL_DIMENSIONS] = {
    let mut m = SOBOL_MATRICES;
    let mut d = 0;
    while d < SOBOL_DIMENSIONS {
        let mut k = 0;
        while k < 32 {
            m[d][k] = m[d][k].reverse_bits();
            k += 1;
        }
        d += 1;
    }
    m
};

/// [`sobol_dimension`] with its bits reversed (see [`SOBOL_MATRICES_REVERSED`]).
#[cfg(test)]
fn sobol_dimension_reversed(mut index: u32, dimension: usize) -> u32 {
    let matrix = &SOBOL_MATRICES_REVERSED[dimension];
    let mut x = 0;
    while index != 0 {
        x ^= matrix[index.trailing_zeros() as usize];
        index &= index - 1;
    }
    x
}

/// Laine and Karras' hash, improved by Vegdahl ("Building a better LK hash", 2021): a
/// permutation of 32-bit numbers in which each bit depends only on the bits below it.
#[inline(always)]
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x ^= x.wrapping_mul(0x3d20_adea);
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | 1);
    x ^= x.wrapping_mul(0x0552_6c56);
    x ^= x.wrapping_mul(0x53a2_2864);
    x
}

/// Owen scrambling of a 32-bit fraction (Burley 2020): each bit flipped by a hash of the
/// bits above it, i.e. a random permutation of every elementary interval's halves.
#[inline]
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// The sample index shuffled by a nested uniform permutation (Burley 2020): the first 2^k
/// indices are a permutation of themselves for every k, so a power-of-two count of samples is
/// still a net. (The scramble alone sends them to another aligned block; the xor with the
/// image of 0 brings them back, which keeps the index, and so the Sobol loop, short.)
#[inline]
pub fn shuffled_index(index: u32, seed: u32) -> u32 {
    owen_scramble(index, seed) ^ owen_scramble(0, seed)
}

/// `x.reverse_bits() & 0xFF_FFFF`: the top 24 bits of `x` reversed (the only ones a point
/// keeps; with AVX2 the compiler reverses eight lanes by byte shuffles).
#[inline(always)]
fn reverse_24(x: u32) -> u32 {
    x.reverse_bits() & 0xFF_FFFF
}

/// `unit_f32(y.reverse_bits())`: the float of the reversal of `y`'s low 24 bits.
#[inline]
fn reversed_unit_f32(y: u32) -> f32 {
    // Below 2^24: the signed conversion is exact and has a vector instruction.
    reverse_24(y << 8) as i32 as f32 * (1.0 / (1u32 << 24) as f32)
}

/// A 32-bit fraction as a float in [0, 1).
#[inline]
pub fn unit_f32(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// Owen-scrambled Sobol points in [`SOBOL_DIMENSIONS`] dimensions that share one index
/// shuffle, so that the dimensions stay stratified together (a photon's light choice, position
/// and direction): quasi-Monte Carlo photon emission (Keller 1997), scrambled per `seed` so
/// that each pass or iteration draws a different set.
#[derive(Clone, Copy, Debug)]
pub struct SobolPoint {
    index: u32,
    seed: u64,
    dimension: usize,
}

impl SobolPoint {
    pub fn new(index: u64, seed: u64) -> SobolPoint {
        // Past 2^32 points the sequence restarts under another scramble.
        let seed = splitmix64(seed ^ (index >> 32));
        SobolPoint {
            index: shuffled_index(index as u32, seed as u32),
            seed,
            dimension: 0,
        }
    }

    /// The next coordinate; None past [`SOBOL_DIMENSIONS`].
    #[inline]
    pub fn next_f32(&mut self) -> Option<f32> {
        let d = self.dimension;
        if d >= SOBOL_DIMENSIONS {
            return None;
        }
        self.dimension += 1;
        let scramble = splitmix64(self.seed ^ (d as u64 + 1)) as u32;
        Some(unit_f32(owen_scramble(
            sobol_dimension(self.index, d),
            scramble,
        )))
    }
}

/// Orthonormal basis around `n` (Duff et al. 2017, branchless).
#[inline]
pub fn basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// `local` (z up) expressed in the frame whose z axis is `n`.
#[inline]
pub fn to_world(local: Vec3, n: Vec3) -> Vec3 {
    let (s, t) = basis(n);
    s * local.x + t * local.y + n * local.z
}

/// Uniform direction on the unit sphere; pdf 1/(4 pi).
#[inline]
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

pub const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

/// Concentric map of the square onto the unit disc (Shirley-Chiu).
#[inline]
pub fn concentric_disc(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, PI / 4.0 * (o.y / o.x))
    } else {
        (o.y, PI / 2.0 - PI / 4.0 * (o.x / o.y))
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

/// Cosine-weighted direction on the hemisphere around +z; pdf cos(theta)/pi.
#[inline]
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disc(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// Uniform direction in the cone of half-angle acos(cos_max) around +z; pdf 1/(2 pi (1 - cos_max)).
#[inline]
pub fn uniform_cone(u: Vec2, cos_max: f32) -> Vec3 {
    let cos_t = 1.0 - u.x * (1.0 - cos_max);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t)
}

/// Uniform barycentrics (b0, b1) on a triangle (the square-root warp).
#[inline]
pub fn uniform_triangle(u: Vec2) -> (f32, f32) {
    let su = u.x.sqrt();
    (1.0 - su, u.y * su)
}

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

/// A discrete distribution proportional to non-negative weights, sampled by inverting its CDF.
#[derive(Clone, Debug, Default)]
pub struct Distribution1D {
    cdf: Vec<f32>,
    pmf: Vec<f32>,
    total: f32,
}

impl Distribution1D {
    pub fn new(weights: &[f32]) -> Self {
        let total: f64 = weights.iter().map(|&w| w.max(0.0) as f64).sum();
        let mut cdf = Vec::with_capacity(weights.len());
        let mut acc = 0.0f64;
        for &w in weights {
            acc += w.max(0.0) as f64;
            cdf.push(if total > 0.0 {
                (acc / total) as f32
            } else {
                0.0
            });
        }
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        let pmf = weights
            .iter()
            .map(|&w| {
                if total > 0.0 {
                    (w.max(0.0) as f64 / total) as f32
                } else {
                    0.0
                }
            })
            .collect();
        Distribution1D {
            cdf,
            pmf,
            total: total as f32,
        }
    }

    pub fn len(&self) -> usize {
        self.pmf.len()
    }
    pub fn is_empty(&self) -> bool {
        self.pmf.is_empty()
    }
    /// Sum of the weights.
    pub fn total(&self) -> f32 {
        self.total
    }
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf[i]
    }

    /// Index i with probability pmf(i); never returns an index of zero weight.
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let mut i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.cdf.len() - 1);
        while self.pmf[i] == 0.0 && i + 1 < self.pmf.len() {
            i += 1;
        }
        while self.pmf[i] == 0.0 && i > 0 {
            i -= 1;
        }
        (i, self.pmf[i])
    }

    /// A point of [0, 1) with density proportional to the weights, each weight spread evenly
    /// over its cell of width 1/len: (the point, its density, the cell).
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        let (i, pmf) = self.sample(u);
        let below = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        // Where u falls within the cell's share of the cdf (0 if u landed in a skipped one).
        let offset = if pmf > 0.0 {
            ((u - below) / pmf).clamp(0.0, ONE_MINUS_EPSILON)
        } else {
            0.0
        };
        let n = self.len() as f32;
        (((i as f32 + offset) / n).min(ONE_MINUS_EPSILON), pmf * n, i)
    }
}

/// The largest f32 below 1.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// A piecewise-constant density on [0, 1)^2 over an `nu` x `nv` grid of cells, proportional
/// to the cells' weights: a marginal distribution over the rows, a conditional one over the
/// cells of each row (pbrt's `PiecewiseConstant2D`).
#[derive(Clone, Debug, Default)]
pub struct Distribution2D {
    conditional: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// `weights` row by row: `weights[v * nu + u]`, `nv` rows of `nu` cells.
    pub fn new(weights: &[f32], nu: usize, nv: usize) -> Self {
        assert_eq!(weights.len(), nu * nv, "a grid of {nu} x {nv} weights");
        let conditional: Vec<Distribution1D> =
            weights.chunks(nu).map(Distribution1D::new).collect();
        let row_totals: Vec<f32> = conditional.iter().map(Distribution1D::total).collect();
        Distribution2D {
            marginal: Distribution1D::new(&row_totals),
            conditional,
        }
    }

    /// Sum of the weights.
    pub fn total(&self) -> f32 {
        self.marginal.total()
    }

    /// A point of [0, 1)^2 and its density (with respect to area on the square); None when
    /// every weight is zero.
    pub fn sample(&self, u: Vec2) -> Option<(Vec2, f32)> {
        if self.total() <= 0.0 {
            return None;
        }
        let (y, pdf_y, row) = self.marginal.sample_continuous(u.y);
        let (x, pdf_x, _) = self.conditional[row].sample_continuous(u.x);
        Some((Vec2::new(x, y), pdf_x * pdf_y))
    }

    /// The density at `p` of [0, 1]^2 (0 outside).
    pub fn pdf(&self, p: Vec2) -> f32 {
        let inside = (0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y);
        if self.total() <= 0.0 || !inside {
            return 0.0;
        }
        let (nu, nv) = (self.conditional[0].len(), self.conditional.len());
        let row = ((p.y * nv as f32) as usize).min(nv - 1);
        let col = ((p.x * nu as f32) as usize).min(nu - 1);
        self.marginal.pmf(row) * self.conditional[row].pmf(col) * (nu * nv) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Sobol sampler's shortened arithmetic gives the points of the plain composition
    /// `owen_scramble(sobol_dimension(shuffled_index(index, s), d), s')`.
    #[test]
    fn sobol_sampler_matches_the_plain_composition() {
        let mut rng = Rng::new(&[7]);
        for d in 0..SOBOL_DIMENSIONS {
            for _ in 0..2000 {
                let (i, s) = (rng.next_u32() >> (rng.next_u32() % 32), rng.next_u32());
                assert_eq!(
                    sobol_dimension_reversed(i, d),
                    sobol_dimension(i, d).reverse_bits()
                );
                assert_eq!(
                    laine_karras(i, s).reverse_bits(),
                    owen_scramble(sobol_dimension(i, 0), s)
                );
                assert_eq!(reverse_24(s), s.reverse_bits() & 0xFF_FFFF);
                assert_eq!(
                    reversed_unit_f32(s).to_bits(),
                    unit_f32(s.reverse_bits()).to_bits()
                );
            }
        }
        for spp in [1, 5, 64, 1000] {
            for index in (0..3 * spp).step_by(7) {
                let mut sampler = Sampler::new(SamplerKind::Sobol, 3, 12345, index, spp);
                let pixel_key = sampler.pixel_key;
                for dim in 0..20 {
                    let (seed, sx, sy) = sobol_seeds(pixel_key, dim);
                    let i = shuffled_index(index, seed);
                    if dim % 3 == 0 {
                        let x = unit_f32(owen_scramble(sobol_dimension(i, 0), sx));
                        assert_eq!(sampler.next_f32().to_bits(), x.to_bits());
                    } else {
                        let x = unit_f32(owen_scramble(sobol_dimension(i, 0), sx));
                        let y = unit_f32(owen_scramble(sobol_dimension(i, 1), sy));
                        let u = sampler.next_2d();
                        assert_eq!((u.x.to_bits(), u.y.to_bits()), (x.to_bits(), y.to_bits()));
                    }
                }
            }
        }
    }

    /// A `sobol` dimension's shuffle and first scramble are seeded differently from every
    /// other dimension's of the same pixel (each hash is a bijection of the dimension), and
    /// every bit of the three seeds is set about half the time over pixels and dimensions.
    #[test]
    fn sobol_seeds_differ_between_dimensions_and_are_balanced() {
        let mut ones = [[0u32; 32]; 3];
        let (pixels, dimensions) = (16u64, 4096u32);
        for pixel in 0..pixels {
            let key = splitmix64(splitmix64(7 ^ 0x5A3F_C0DE) ^ pixel);
            let mut seen = [
                std::collections::HashSet::new(),
                std::collections::HashSet::new(),
            ];
            for d in 0..dimensions {
                let (a, b, c) = sobol_seeds(key, d);
                assert!(
                    seen[0].insert(a),
                    "pixel {pixel}: shuffle seed of {d} repeats"
                );
                assert!(
                    seen[1].insert(b),
                    "pixel {pixel}: scramble seed of {d} repeats"
                );
                for (s, seed) in [a, b, c].into_iter().enumerate() {
                    for (bit, n) in ones[s].iter_mut().enumerate() {
                        *n += seed >> bit & 1;
                    }
                }
            }
        }
        // 65536 values a bit: a fair bit is within 1 % of one half with odds of 1 in 10^6.
        let n = (pixels * dimensions as u64) as f64;
        for (s, bits) in ones.iter().enumerate() {
            for (bit, &k) in bits.iter().enumerate() {
                let f = k as f64 / n;
                assert!((f - 0.5).abs() < 0.01, "seed {s} bit {bit} set in {f}");
            }
        }
    }

    /// A block of Sobol dimensions, vectorised or not, holds each dimension's point as
    /// `sobol_lane` computes it alone; dimension 1's five steps are the matrix's product.
    #[test]
    fn sobol_block_matches_each_lane() {
        let mut rng = Rng::new(&[11]);
        for _ in 0..3000 {
            let i = rng.next_u32() >> (rng.next_u32() % 32);
            assert_eq!(sobol_1_reversed(i), sobol_dimension_reversed(i, 1));
        }
        for _ in 0..500 {
            let pixel_key = (rng.next_u32() as u64) << 32 | rng.next_u32() as u64;
            let index_reversed = rng.next_u32();
            let first = rng.next_u32() % 100;
            let mut fast = SobolBlock::EMPTY;
            sobol_block(pixel_key, index_reversed, first, &mut fast);
            let mut plain = SobolBlock::EMPTY;
            sobol_block_lanes(pixel_key, index_reversed, first, &mut plain);
            for k in 0..SOBOL_BLOCK {
                let (x, y) = sobol_lane(pixel_key, first + k as u32, index_reversed);
                for block in [&fast, &plain] {
                    assert_eq!(block.x[k].to_bits(), x.to_bits());
                    assert_eq!(block.y[k].to_bits(), y.to_bits());
                }
            }
        }
    }

    #[test]
    fn distribution_never_picks_zero_weight() {
        let d = Distribution1D::new(&[0.0, 1.0, 0.0, 3.0, 0.0]);
        for k in 0..1000 {
            let (i, p) = d.sample(k as f32 / 1000.0);
            assert!(i == 1 || i == 3, "picked {i}");
            assert!(p > 0.0);
        }
        assert_eq!(d.sample(0.9999).0, 3);
    }

    #[test]
    fn distribution2d_density_is_the_normalised_weights() {
        let w = [0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 3.0, 0.5, 4.0];
        let d = Distribution2D::new(&w, 3, 3);
        let total: f32 = w.iter().sum();
        let mut rng = Rng::new(&[3]);
        let mut counts = [0u32; 9];
        let n = 90_000;
        for _ in 0..n {
            let (p, pdf) = d.sample(rng.next_2d()).unwrap();
            let cell = (p.y * 3.0) as usize * 3 + (p.x * 3.0) as usize;
            assert!(w[cell] > 0.0, "sampled a cell of zero weight");
            assert!((pdf - w[cell] / total * 9.0).abs() < 1e-5);
            assert!((d.pdf(p) - pdf).abs() < 1e-5);
            counts[cell] += 1;
        }
        for (c, w) in counts.iter().zip(w) {
            let want = w / total * n as f32;
            assert!(
                (*c as f32 - want).abs() < 5.0 * want.sqrt().max(1.0),
                "{c} vs {want}"
            );
        }
        assert!(
            Distribution2D::new(&[0.0; 4], 2, 2)
                .sample(Vec2::splat(0.5))
                .is_none()
        );
    }

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

    #[test]
    fn basis_is_orthonormal() {
        let mut rng = Rng::new(&[1]);
        for _ in 0..1000 {
            let n = uniform_sphere(rng.next_2d());
            let (s, t) = basis(n);
            assert!((s.length() - 1.0).abs() < 1e-4 && (t.length() - 1.0).abs() < 1e-4);
            assert!(s.dot(t).abs() < 1e-4 && s.dot(n).abs() < 1e-4 && t.dot(n).abs() < 1e-4);
        }
    }
}
