//! The [`Sampler`] every integrator draws from: the interface each kind of sampler implements
//! ([`SamplerImpl`], pbrt-v4's `Sampler` interface), the [`samplers!`] macro that makes the
//! dispatching enums and the table of factories from one line per kind, and how a camera
//! sample's sampler is made ([`Sampler::new`], [`PixelSamplers`]).
//!
//! The kinds are one file each in `sampling/` (`independent.rs`, `stratified.rs`, `sobol.rs`),
//! listed in `sampling/mod.rs`. docs/extending.md adds one.
//!
//! A sampler is a tagged union of the kinds with static dispatch (pbrt-v4's `Sampler`), not a
//! trait object: it is in the innermost loop, and each request is a `match` on the tag, which
//! is the same for a whole render and so predicts perfectly, then the kind's own code, inlined
//! (a call only for `stratified`'s permutations and for each block of `sobol` points).

use super::rng::{Rng, hash_keys, splitmix64};
use super::{AnyKind, AnySampler, SAMPLERS};
use crate::error::Result;
use crate::props::Properties;
use crate::registry;
use glam::Vec2;

/// What a kind of sampler implements (one file each in `sampling/`): the numbers one camera
/// sample draws, dimension after dimension (pbrt-v4's `StartPixelSample`, then `Get1D` /
/// `Get2D` in a fixed order), which depend on the kind's settings and on (seed, pixel, sample
/// index) alone, so that an image is the same for any thread count and any split into parts.
pub trait SamplerImpl: Clone + std::fmt::Debug {
    /// The kind's parameters as the scene gives them (`stratified`'s `jitter`; a unit struct
    /// for none): what a [`SamplerKind`] of the kind holds, made by its factory. Each kind's
    /// is a type of its own (`SamplerKind` is `From` each).
    type Settings: Copy + std::fmt::Debug + PartialEq + Eq;
    /// Whether [`SampleStart::rng`] is made: the camera sample's independent stream (a hash
    /// of its keys), which a sampler that draws no random numbers (`sobol`) does not need.
    const USES_RNG: bool = true;
    /// Whether [`SampleStart::pixel_key`] is made (the independent sampler has no pattern to
    /// decorrelate between pixels).
    const USES_PIXEL_KEY: bool = true;

    /// The sampler of one camera sample.
    fn start(settings: Self::Settings, sample: SampleStart) -> Self;
    /// Uniform in [0, 1).
    fn next_f32(&mut self) -> f32;
    /// Uniform in [0, 1)^2, the two coordinates stratified together where the kind can.
    fn next_2d(&mut self) -> Vec2;
}

/// What a sampler's file registers (its `FACTORY`): its name in scene files (`[render]
/// sampler`), a one-line description, and `create`, which reads the kind's parameters from the
/// `[render]` bag into its settings. `samplers!` makes of it the `registry::Factory` of the
/// table, which wraps the settings in a [`SamplerKind`]. Unlike a medium's, a
/// sampler's factory makes no object (a sampler is made per camera sample, from the settings)
/// and reads neither nested tables nor files.
pub struct SamplerFactory<S: SamplerImpl> {
    pub name: &'static str,
    pub description: &'static str,
    pub create: fn(&Properties<'_>) -> Result<S::Settings>,
}

/// Which camera sample a sampler draws for.
#[derive(Clone, Debug)]
pub struct SampleStart {
    /// The sample's independent stream, keyed by (seed, pixel, index) or the integrator's keys
    /// ([`Sampler::with_keys`]); a stream never to be drawn from when not `USES_RNG`.
    pub rng: Rng,
    /// Hash of (seed, pixel): what decorrelates the patterns of neighbouring pixels; zero
    /// when not `USES_PIXEL_KEY`.
    pub pixel_key: u64,
    /// The sample's index within its pixel (past `spp` for integrators that take samples
    /// without a bound, as sppm's iterations).
    pub index: u32,
    /// Samples the pixel takes, at least 1.
    pub spp: u32,
}

/// Declares the files of the samplers and what is made of them, one line per file:
///
/// ```text
/// samplers! {
///     /// The built-in samplers.
///     pub const SAMPLERS = [
///         independent::IndependentSampler,
///     ];
/// }
/// ```
///
/// declares `pub mod independent;` (the file `sampling/independent.rs`, which defines
/// `IndependentSampler`, implementing [`SamplerImpl`], and ends with `pub const FACTORY:
/// SamplerFactory<IndependentSampler>`), re-exports `IndependentSampler`, and makes
///
/// * `AnyKind`, what a [`SamplerKind`] holds: a variant per line (named by the module) holding
///   the kind's `Settings`, and `From` each kind's `Settings` for `SamplerKind`;
/// * `AnySampler`, what a [`Sampler`] holds: a variant per line holding the kind's sampler,
///   with `next_f32` and `next_2d`, each a `match` on the variant;
/// * `SAMPLERS`, the table of the factories (`registry::Factory<SamplerKind>`, each the
///   file's `FACTORY` with its settings wrapped in a `SamplerKind`), in the lines' order.
macro_rules! samplers {
    (
        $(#[$attr:meta])*
        $vis:vis const $table:ident = [$($module:ident::$ty:ident),* $(,)?];
    ) => {
        $(pub mod $module;)*
        $(pub use $module::$ty;)*

        $(#[$attr])*
        $vis const $table: &[$crate::registry::Factory<SamplerKind>] = &[$(
            $crate::registry::Factory {
                name: $module::FACTORY.name,
                description: $module::FACTORY.description,
                create: |bag, _, _| Ok(Box::new(($module::FACTORY.create)(bag)?.into())),
            }
        ),*];

        /// The settings of a kind of sampler (see [`SamplerKind`]).
        #[allow(non_camel_case_types)]
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        enum AnyKind {
            $($module(<$ty as $crate::sampling::SamplerImpl>::Settings),)*
        }

        $(
            impl From<<$ty as $crate::sampling::SamplerImpl>::Settings> for SamplerKind {
                fn from(settings: <$ty as $crate::sampling::SamplerImpl>::Settings) -> Self {
                    SamplerKind(AnyKind::$module(settings))
                }
            }
        )*

        impl AnyKind {
            fn name(&self) -> &'static str {
                match self {
                    $(AnyKind::$module(_) => $module::FACTORY.name,)*
                }
            }

            #[inline]
            fn uses_rng(&self) -> bool {
                match self {
                    $(AnyKind::$module(_) =>
                        <$ty as $crate::sampling::SamplerImpl>::USES_RNG,)*
                }
            }

            #[inline]
            fn uses_pixel_key(&self) -> bool {
                match self {
                    $(AnyKind::$module(_) =>
                        <$ty as $crate::sampling::SamplerImpl>::USES_PIXEL_KEY,)*
                }
            }

            /// The sampler of camera sample `index` of `spp`; the stream and the pixel key are
            /// made only for the kinds that use them.
            #[inline]
            fn start(
                &self,
                rng: impl FnOnce() -> $crate::sampling::Rng,
                pixel_key: impl FnOnce() -> u64,
                index: u32,
                spp: u32,
            ) -> AnySampler {
                use $crate::sampling::SamplerImpl;
                match *self {
                    $(AnyKind::$module(settings) => AnySampler::$module(<$ty>::start(
                        settings,
                        $crate::sampling::SampleStart {
                            rng: if <$ty>::USES_RNG {
                                rng()
                            } else {
                                $crate::sampling::Rng::UNUSED
                            },
                            pixel_key: if <$ty>::USES_PIXEL_KEY { pixel_key() } else { 0 },
                            index,
                            spp: spp.max(1),
                        },
                    )),)*
                }
            }
        }

        /// The sampler of one camera sample, of any kind (see [`Sampler`]).
        #[allow(non_camel_case_types)]
        // A one-byte tag: the requests' test loads a byte (with a tag as wide as the
        // fields, `sobol` renders took about 0.05 % more instructions).
        #[derive(Clone, Debug)]
        #[repr(u8)]
        enum AnySampler {
            $($module($ty),)*
        }

        impl AnySampler {
            #[inline]
            fn next_f32(&mut self) -> f32 {
                match self {
                    $(AnySampler::$module(s) => $crate::sampling::SamplerImpl::next_f32(s),)*
                }
            }

            #[inline]
            fn next_2d(&mut self) -> glam::Vec2 {
                match self {
                    $(AnySampler::$module(s) => $crate::sampling::SamplerImpl::next_2d(s),)*
                }
            }
        }
    };
}
pub(crate) use samplers;

/// Which points a render's [`Sampler`]s hand out (`[render] sampler` and its parameters): one
/// of the kinds of [`SAMPLERS`](super::SAMPLERS), with its settings. Made by the kind's
/// factory, or from its settings: `SamplerKind::from(Stratified { jitter: true })`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SamplerKind(pub(super) AnyKind);

impl SamplerKind {
    /// The names `[render] sampler` takes: those of the table, in its order.
    pub const NAMES: [&'static str; SAMPLERS.len()] =
        registry::name_array::<_, { SAMPLERS.len() }>(SAMPLERS);

    /// Its name in scene files.
    pub fn name(&self) -> &'static str {
        self.0.name()
    }
}

/// The numbers one camera sample draws, dimension after dimension: the first 2-D request is
/// the position on the film. Integrators call [`Sampler::next_f32`] and [`Sampler::next_2d`];
/// which points come back depends on the kind ([`SamplerImpl`]), and on (seed, pixel, sample
/// index) alone.
#[derive(Clone, Debug)]
pub struct Sampler(pub(super) AnySampler);

impl Sampler {
    /// Uniform in [0, 1).
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        self.0.next_f32()
    }

    /// Uniform in [0, 1)^2; the two coordinates are stratified together.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        self.0.next_2d()
    }

    /// Sample `index` of `spp` of `pixel` (any number that names the pixel, e.g. y width + x).
    /// With `independent` the numbers are those of `Rng::new(&[seed, pixel, index])`.
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
        Sampler(
            kind.0
                .start(|| Rng::new(keys), || pixel_key(seed, pixel), index, spp),
        )
    }
}

/// A sampler's pixel key: the hash of (seed, pixel) that decorrelates the patterns of
/// neighbouring pixels.
#[inline]
fn pixel_key(seed: u64, pixel: u64) -> u64 {
    splitmix64(splitmix64(seed ^ 0x5A3F_C0DE) ^ pixel)
}

/// What the samplers of one pixel share: the hashes of the seed and the pixel (the pixel key,
/// and the independent stream's keys before the sample index), made once for all the pixel's
/// samples. [`PixelSamplers::sample`] gives the sampler [`Sampler::new`] gives.
#[derive(Clone, Copy, Debug)]
pub struct PixelSamplers {
    kind: SamplerKind,
    /// `Rng::new`'s hash of (seed, pixel), before the sample index (for the kinds that use
    /// the stream).
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
            keys_hash: if kind.0.uses_rng() {
                hash_keys(super::rng::RNG_KEYS_START, &[seed, pixel])
            } else {
                0
            },
            pixel_key: if kind.0.uses_pixel_key() {
                pixel_key(seed, pixel)
            } else {
                0
            },
            spp,
        }
    }

    /// The sampler of the pixel's sample `index`: `Sampler::new(kind, seed, pixel, index, spp)`.
    #[inline]
    pub fn sample(&self, index: u32) -> Sampler {
        Sampler(self.kind.0.start(
            || Rng::from_hash(hash_keys(self.keys_hash, &[index as u64])),
            || self.pixel_key,
            index,
            self.spp,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::independent::Independent;
    use crate::sampling::sobol::Sobol;
    use crate::sampling::stratified::Stratified;

    /// A pixel's samplers made once per pixel draw what each sample's sampler keyed by
    /// (seed, pixel, index) draws, for every kind.
    #[test]
    fn pixel_samplers_draw_what_keyed_samplers_draw() {
        for kind in [
            SamplerKind::from(Independent),
            SamplerKind::from(Stratified { jitter: true }),
            SamplerKind::from(Stratified { jitter: false }),
            SamplerKind::from(Sobol),
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
