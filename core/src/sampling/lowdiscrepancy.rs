//! Sobol points, Owen-scrambled (Burley 2020): the `sobol` sampler's blocks of padded
//! dimensions, and the shared-shuffle points of photon emission ([`SobolPoint`]).

use super::rng::{hash32, splitmix64};

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
    pub(super) const EMPTY: SobolBlock = SobolBlock {
        x: [0.0; SOBOL_BLOCK],
        y: [0.0; SOBOL_BLOCK],
    };
}

/// The Owen-scrambled Sobol points of dimensions `first..first + SOBOL_BLOCK` of the sample
/// whose pixel key and reversed index are given (the `sobol` sampler's fields), into `block`.
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
/// hash, against about 105 one at a time with a data-dependent loop. Integer arithmetic,
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

/// The three 32-bit seeds of a `sobol` dimension (the index shuffle's, and the scrambles of
/// the point's two coordinates), from the pixel's key and the dimension: two 32-bit hashes,
/// the first of the key's low half and the dimension, the second of the first and the key's
/// high half; the third seed mixes the halves of both. 32-bit arithmetic because it runs in
/// AVX2's eight 32-bit lanes (a 64-bit `splitmix64` per dimension has no AVX2
/// multiply, and would be a third of a block's instructions). The seeds need to differ
/// from dimension to dimension and pixel to pixel and look random, not be independent bits:
/// for one pixel each hash is a bijection of the dimension, so no two dimensions share a
/// shuffle or a scramble.
#[inline(always)]
fn sobol_seeds(pixel_key: u64, dimension: u32) -> (u32, u32, u32) {
    let h1 = hash32(pixel_key as u32 ^ dimension.wrapping_mul(0x9E37_79B9));
    let h2 = hash32(h1 ^ (pixel_key >> 32) as u32);
    (h1, h2, ((h1 >> 16) | (h2 << 16)) ^ 0x9E37_79B9)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{Rng, Sampler, SamplerKind};

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
                let kind = SamplerKind::from(crate::sampling::sobol::Sobol);
                let mut sampler = Sampler::new(kind, 3, 12345, index, spp);
                let crate::sampling::AnySampler::sobol(sobol) = &sampler.0 else {
                    unreachable!("a sobol sampler")
                };
                let pixel_key = sobol.pixel_key;
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
}
