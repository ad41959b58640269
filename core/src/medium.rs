//! Participating media: the `Medium` interface every integrator uses, free-flight distance
//! sampling and its weights, and the table of built-in media ([`MEDIA`]), one file each in
//! `medium/` (`homogeneous.rs`) that reads its parameters and ends with its factory; phase
//! functions are `medium/phase.rs`. Where media are in a scene (which medium a point or ray is
//! in, and how it changes at boundaries) is the scene's business: `Scene::medium_at`,
//! `Scene::medium_after` and `Scene::transmittance`. docs/extending.md adds a medium.
//!
//! Free-flight sampling in a chromatic medium uses one-sample MIS over the colour channels
//! (the "spectral MIS" of Wilkie et al. 2014 with the balance heuristic): t is drawn from
//! sigma_t,c exp(-sigma_t,c t) for a channel c chosen uniformly, and the estimate is divided by
//! the average over channels of the pdfs, not by the pdf of the channel used; dividing by the
//! channel's own pdf alone would be biased in the channels whose sigma_t is zero and of
//! unbounded variance in the others. Per event ([`FreeFlight::weight`], pbrt-v3's homogeneous
//! medium) the average is over one distance; along a whole path ([`HeroChannel`], pbrt-v4's
//! `r_u`) the channel is chosen once per path and the average is over the pdfs of the whole
//! path, which keeps the weight of every channel below 3 however many events the path has.

use crate::Rgb;
use crate::geometry::Ray;
use glam::Vec3;

pub mod grid;
mod phase;
pub mod tracking;
pub use phase::Phase;

crate::registry::builtins! {
    /// The built-in kinds of medium, one line each (a file in `medium/` that ends with its
    /// `FACTORY`): what a `[media]` table's `type` names.
    pub const MEDIA: [dyn Medium] = [
        homogeneous,
        heterogeneous,
    ];
}
pub use heterogeneous::Heterogeneous;
pub use homogeneous::Homogeneous;

/// A free-flight distance sample along a ray segment of length `tmax` (to the next surface, or
/// infinity).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FreeFlight {
    /// Distance of the scattering event; `tmax` if the sample passed the whole segment.
    pub t: f32,
    /// Whether a real scattering event happened in the medium (otherwise the path goes on at
    /// the surface at `tmax`, or escapes).
    pub scattered: bool,
    /// The integrand's factor: sigma_s Tr(t) at a scattering event, Tr(tmax) otherwise.
    pub f: Rgb,
    /// Per channel c, the probability (density, 1/m, at a scattering event) of this outcome
    /// had channel c been sampled: sigma_t,c Tr_c(t), or Tr_c(tmax) when passing.
    pub pdf: Rgb,
    /// The medium's emission integrand at a scattering event, Tr(t) sigma_a(t) Le(t) (zero
    /// when passing, and in a medium that does not emit): the collision estimator of the
    /// emission along the segment, int Tr sigma_a Le dt, is this over the pdf.
    pub emitted: Rgb,
}

impl FreeFlight {
    /// What the throughput is multiplied by with one-sample MIS over the channels of this
    /// event alone (channel chosen uniformly): f / mean(pdf). Each channel's expectation is
    /// exactly its transmittance-weighted integrand, and each channel's weight is at most 3
    /// sigma_s / sigma_t (scattered) or 3 (passed).
    pub fn weight(&self) -> Rgb {
        let pdf = crate::average(self.pdf);
        if pdf > 0.0 { self.f / pdf } else { Rgb::ZERO }
    }

    /// What the throughput before this event is multiplied by for the emission the medium
    /// adds here (one-sample MIS over the channels of this event, as [`Self::weight`]).
    pub fn emission_weight(&self) -> Rgb {
        let pdf = crate::average(self.pdf);
        if pdf > 0.0 {
            self.emitted / pdf
        } else {
            Rgb::ZERO
        }
    }
}

/// The colour channel chosen by a uniform number in [0, 1).
#[inline]
pub fn channel(u: f32) -> usize {
    ((u * 3.0) as usize).min(2)
}

/// Spectral MIS over a whole path (the hero channel): every free-flight sample of the path
/// uses the same channel, and the path's throughput is its integrand divided by the average
/// over channels of the path's pdf under each channel. `r` holds those per-channel path pdfs,
/// scaled to mean 1 after every event so that neither it nor the throughput overflows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeroChannel {
    pub channel: usize,
    pub r: Rgb,
}

impl HeroChannel {
    /// A path's hero channel, chosen uniformly by `u`.
    pub fn new(u: f32) -> Self {
        HeroChannel {
            channel: channel(u),
            r: Rgb::ONE,
        }
    }

    /// For a free-flight sample of the path (drawn with `self.channel`) and before
    /// [`Self::update`] accounts for it: the factor the throughput is multiplied by for the
    /// emission the medium adds at the event.
    pub fn emission(&self, flight: &FreeFlight) -> Rgb {
        let mean = crate::average(self.r * flight.pdf);
        if mean > 0.0 {
            flight.emitted / mean
        } else {
            Rgb::ZERO
        }
    }

    /// Accounts for a free-flight sample of the path (drawn with `self.channel`); returns the
    /// factor the throughput is multiplied by.
    pub fn update(&mut self, flight: &FreeFlight) -> Rgb {
        let r = self.r * flight.pdf;
        let mean = crate::average(r);
        if mean <= 0.0 {
            return Rgb::ZERO;
        }
        self.r = r / mean;
        flight.f / mean
    }
}

/// Transmittance exp(-sigma_t d) per channel. A channel with sigma_t = 0 transmits fully even
/// over an infinite distance (0 x inf would be NaN).
#[inline]
pub fn transmittance_homogeneous(sigma_t: Rgb, d: f32) -> Rgb {
    let tr = |s: f32| if s == 0.0 { 1.0 } else { (-s * d).exp() };
    // A grey medium (the common case) needs one exponential, not three: the same values.
    if sigma_t.x == sigma_t.y && sigma_t.y == sigma_t.z {
        return Rgb::splat(tr(sigma_t.x));
    }
    Rgb::new(tr(sigma_t.x), tr(sigma_t.y), tr(sigma_t.z))
}

/// Density of the free-flight distance t of [`Homogeneous::sample_free_flight`] (spectral MIS,
/// channels chosen uniformly): the mean over channels of sigma_t,c exp(-sigma_t,c t).
#[inline]
pub fn free_flight_pdf(sigma_t: Rgb, t: f32) -> f32 {
    crate::average(sigma_t * transmittance_homogeneous(sigma_t, t))
}

/// Probability that a free-flight sample passes a segment of length `tmax`: the mean over
/// channels of exp(-sigma_t,c tmax).
#[inline]
pub fn free_flight_pass_probability(sigma_t: Rgb, tmax: f32) -> f32 {
    crate::average(transmittance_homogeneous(sigma_t, tmax))
}

/// A participating medium: the interface every integrator uses (Mitsuba's `Medium`,
/// pbrt-v4's `Medium`), so that a new kind of medium is one implementation of this trait and no
/// integrator changes. Positions and rays are in world space; a medium knows nothing of its
/// boundaries (the scene's medium interfaces say where it is).
pub trait Medium: Send + Sync + std::fmt::Debug {
    /// Whether the medium neither absorbs nor scatters anywhere: integrators skip it entirely,
    /// so that an empty medium renders exactly (bit for bit) as no medium.
    fn is_vacuum(&self) -> bool;
    /// Absorption coefficient (1/m) at `p`.
    fn sigma_a(&self, p: Vec3) -> Rgb;
    /// Scattering coefficient (1/m) at `p`.
    fn sigma_s(&self, p: Vec3) -> Rgb;
    /// Extinction coefficient (1/m) at `p`.
    fn sigma_t(&self, p: Vec3) -> Rgb {
        self.sigma_a(p) + self.sigma_s(p)
    }
    fn phase(&self) -> Phase;
    /// Emitted radiance Le at `p` (W m^-2 sr^-1, the same in every direction); the medium adds
    /// sigma_a Le per unit length along a ray (pbrt-v4's media). Zero by default.
    fn emission(&self, _p: Vec3) -> Rgb {
        Rgb::ZERO
    }
    /// Whether [`Self::emission`] is anywhere other than zero (false by default).
    fn is_emissive(&self) -> bool {
        false
    }
    /// Transmittance along `ray` from its origin over the distance `d` (which may be
    /// infinite; `ray.dir` is a unit vector).
    fn transmittance(&self, ray: &Ray, d: f32) -> Rgb;
    /// Samples a free-flight distance along `ray` within (0, `tmax`) with channel `channel`'s
    /// density (see the module comment for the weights); `u` is uniform in [0, 1).
    fn sample_free_flight(&self, ray: &Ray, tmax: f32, channel: usize, u: f32) -> FreeFlight;
    /// The medium's coefficients if they are the same everywhere, else None (the default).
    /// For estimates that evaluate many transmittances in one medium (the beam x beam
    /// gather: two per beam a camera ray crosses), so that they compute exp(-sigma_t d)
    /// inline rather than through this trait's virtual calls; what they compute is the same.
    fn homogeneous(&self) -> Option<Homogeneous> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vacuum_channels_transmit_over_infinite_distances() {
        let tr = transmittance_homogeneous(Rgb::new(0.0, 1.0, 2.0), f32::INFINITY);
        assert_eq!(tr, Rgb::new(1.0, 0.0, 0.0));
        let m = Homogeneous {
            sigma_a: Rgb::new(0.0, 1.0, 0.0),
            sigma_s: Rgb::new(0.0, 0.0, 2.0),
            phase: Phase::Isotropic,
            emission: Rgb::ZERO,
        };
        // Channel 0 (vacuum) chosen: the sample passes with weight Tr / P(pass) = 1 / (1/3).
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        let f = m.sample_free_flight(&ray, f32::INFINITY, channel(0.1), 0.5);
        assert!(!f.scattered);
        assert_eq!(f.weight(), Rgb::new(3.0, 0.0, 0.0));
        let mut hero = HeroChannel::new(0.1);
        assert_eq!(hero.update(&f), Rgb::new(3.0, 0.0, 0.0));
        assert_eq!(hero.r, Rgb::new(3.0, 0.0, 0.0));
    }
}
