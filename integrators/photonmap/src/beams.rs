//! Photon beams and the beam x beam estimate (Jarosz, Nowrouzezahrai, Sadeghi and Jensen, "A
//! comprehensive theory of volumetric radiance estimation using photon points and beams",
//! TOG 2011, the "beam x beam 1D" estimate).
//!
//! **Beams.** A photon's flight through a medium is a beam: its start x_b, direction w_b,
//! length, the flux Phi_b it carries at the start, its medium. *Long* beams run to the next
//! surface (or out of the scene); the flux along them falls as the transmittance Tr_b(t). *Short*
//! beams end at the photon's next scattering event (the free-flight sample), so they carry the
//! flux unattenuated: the event "the flight passes t" has probability Tr_b(t) (with spectral MIS
//! over the colour channels, the path's channel pdfs times Tr), which replaces the
//! transmittance. Either way the photon walks on as before; only what is recorded differs.
//!
//! **The estimate.** A photon beam of flux Phi along a line is a fluence concentrated on the
//! line: phi(x) = Phi Tr_b(t) delta_2(x_perp), delta_2 over the plane perpendicular to the
//! beam. The radiance a camera ray (the *query beam*, direction w, medium with sigma_s and
//! phase p) gathers is integral Tr_c(t_c) sigma_s p(w_b, -w) phi(x(t_c)) dt_c. Along the camera
//! ray the perpendicular offset from the beam has one fixed coordinate, the distance u between
//! the two lines (along their common perpendicular), and one that moves at speed sin(theta),
//! theta the angle between the lines; so the integral of delta_2 along the ray is
//! delta(u) / sin(theta). Blurring delta(u) by a 1-D kernel K1 of radius r gives the beam x
//! beam estimate:
//!
//! ```text
//! L_m(x, w) ~= sum_b Phi_b W_b(t_b) sigma_s(x_c) p(w_b . -w) Tr_c(t_c) K1(u_b, r) / sin(theta_b)
//! ```
//!
//! with t_c, t_b the parameters of the closest approach on the camera ray and on the beam
//! (both within their segments), W_b = Tr_b(t_b) (long beams) or Tr_b(t_b) / mean_c(r_c
//! Tr_b,c(t_b)) (short beams; 1 in a grey medium), r_c the photon path's hero-channel pdf
//! ratios. K1 is the kernel profile normalised in 1-D: integral_{-r}^{r} K1(u, r) du = 1 (box:
//! 1 / (2 r)). Integrating the estimate over the camera rays of a pencil crossing the beam
//! gives back Phi Tr_b per unit length of beam whatever the angle, which the tests check.
//!
//! **The map.** Beams are cut into pieces of 16 widths (a long diagonal beam's box would be
//! mostly empty), and the pieces' boxes, grown by what a disc of radius r across the beam
//! reaches on each axis, go into a BVH of boxes ([`TwoLevelBvh`]: a top tree of median splits
//! over core's `Accel`s, obvhs' compressed wide BVH8 with each box as a flat triangle spanning
//! it, built in parallel), so that a camera segment is traversed with core's eight-wide AVX2
//! node test where the processor has it, as a shadow ray that nothing blocks: it is offered
//! every piece whose box it crosses. A piece is first
//! rejected by the distance between the two lines (no division, no square root: most pieces
//! a ray passes are farther than r), and counts the crossing only if the closest point on the
//! beam lies within the piece, so a beam is counted once.

use crate::map::Photon;
use crate::twolevel::TwoLevelBvh;
use foton_core::api::{
    Medium, NormalizedKernel, Phase, Properties, Ray, Result, Rgb, Scene, Shape, Vec3,
    transmittance_homogeneous,
};
use rayon::prelude::*;

/// Which flight segments a photon records (module comment).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BeamKind {
    /// From the segment's start to the photon's next scattering event (or the surface).
    Short,
    /// From the segment's start to the next surface, with the transmittance along it.
    Long,
}

impl BeamKind {
    pub fn name(self) -> &'static str {
        match self {
            BeamKind::Short => "short",
            BeamKind::Long => "long",
        }
    }
}

/// One photon's flight through a medium.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Beam {
    pub origin: Vec3,
    /// Unit direction the photon travels.
    pub dir: Vec3,
    pub length: f32,
    /// Flux at the start (W).
    pub flux: Rgb,
    /// Short beams: the photon path's per-channel pdf ratios before this flight (spectral MIS;
    /// [`foton_core::api::HeroChannel::r`]).
    pub hero_r: Rgb,
    pub medium: u32,
    /// Scattering events of a light path that scatters once on this beam (the photon's events
    /// before it plus that one).
    pub depth: u32,
    pub kind: BeamKind,
}

impl Beam {
    /// W_b(t): the fraction of the start flux the beam stands for at distance t (module
    /// comment), in medium `m`.
    #[inline]
    pub fn weight(&self, m: &dyn Medium, t: f32) -> Rgb {
        self.weight_of(m.transmittance(&Ray::new(self.origin, self.dir), t))
    }

    /// W_b(t) from the beam's transmittance Tr_b(t).
    #[inline]
    pub fn weight_of(&self, tr: Rgb) -> Rgb {
        match self.kind {
            BeamKind::Long => tr,
            BeamKind::Short => {
                let p = foton_core::api::average(self.hero_r * tr);
                if p > 0.0 { tr / p } else { Rgb::ZERO }
            }
        }
    }

    /// A volume photon at the beam's start, for the tools (`foton photons`).
    pub fn as_photon(&self) -> Photon {
        Photon::new(self.origin, self.flux, -self.dir, Vec3::ZERO).with_depth(self.depth)
    }
}

/// Where two lines pass closest: the query ray o_c + t_c w_c and the beam o_b + t_b w_b.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    pub t_c: f32,
    pub t_b: f32,
    /// Distance between the lines.
    pub u: f32,
    /// sin of the angle between them.
    pub sin: f32,
}

/// Below this sine the lines are taken as parallel: the 1-D kernel across them is undefined
/// (the estimate's 1 / sin(theta) is integrable over directions, but a parallel pair has no
/// closest point).
pub const MIN_SIN: f32 = 1e-4;

/// The closest approach of two lines with unit directions (None if nearly parallel).
#[inline]
pub fn closest_approach(o_c: Vec3, w_c: Vec3, o_b: Vec3, w_b: Vec3) -> Option<Crossing> {
    let n = w_c.cross(w_b);
    closest_approach_from(o_b - o_c, n, n.length_squared(), w_c, w_b)
}

/// [`closest_approach`] from d = o_b - o_c, n = w_c x w_b and |n|^2 (computed before).
#[inline]
fn closest_approach_from(d: Vec3, n: Vec3, sin2: f32, w_c: Vec3, w_b: Vec3) -> Option<Crossing> {
    if sin2 < MIN_SIN * MIN_SIN {
        return None;
    }
    // Solve o_c + t_c w_c + s n = o_b + t_b w_b by Cramer's rule with n = w_c x w_b.
    let t_c = d.cross(w_b).dot(n) / sin2;
    let t_b = d.cross(w_c).dot(n) / sin2;
    Some(Crossing {
        t_c,
        t_b,
        u: d.dot(n).abs() / sin2.sqrt(),
        sin: sin2.sqrt(),
    })
}

/// A kernel normalised in one dimension, from a kernel normalised in two (core's
/// [`NormalizedKernel`], so kernel plugins are checked as everywhere): K1(u, r) =
/// w(|u| / r) / (r integral_{-1}^{1} w(|t|) dt).
pub struct Kernel1d<'a> {
    kernel: &'a NormalizedKernel,
    /// 1 / integral_{-1}^{1} of the 2-D weight at radius 1.
    inv_norm: f32,
    /// The box kernel's constant 2-D weight at radius 1 (the same value `weight` would
    /// compute, without the kernel's call per crossing).
    constant: Option<f32>,
}

impl<'a> Kernel1d<'a> {
    /// The kernel with its 1-D normalisation ([`Kernel1d::norm`]: compute it once).
    pub fn new(kernel: &'a NormalizedKernel) -> Self {
        Self::with_norm(kernel, Self::norm(kernel))
    }

    /// The kernel with a normalisation [`Kernel1d::norm`] computed before.
    pub fn with_norm(kernel: &'a NormalizedKernel, inv_norm: f32) -> Self {
        // Core's built-in "box" (kernel plugins cannot take a built-in's name).
        let constant = (kernel.name() == "box").then(|| kernel.weight_2d(0.0, 1.0));
        Kernel1d {
            kernel,
            inv_norm,
            constant,
        }
    }

    /// 1 / integral_{-1}^{1} of the kernel's 2-D weight at radius 1.
    pub fn norm(kernel: &NormalizedKernel) -> f32 {
        // Simpson's rule on [0, 1] (the profile is smooth or a step at 1).
        const N: usize = 4096;
        let h = 1.0 / N as f64;
        let w = |i: usize| kernel.weight_2d((i as f64 * h) as f32, 1.0) as f64;
        let mut s = w(0) + w(N);
        for i in 1..N {
            s += w(i) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        let integral = 2.0 * s * h / 3.0;
        if integral > 0.0 {
            (1.0 / integral) as f32
        } else {
            0.0
        }
    }

    /// K1(u, r): the weight of a beam at distance u across the query, per unit length.
    #[inline]
    pub fn weight(&self, u: f32, r: f32) -> f32 {
        if u > r {
            return 0.0;
        }
        let w = match self.constant {
            Some(w) => w,
            None => self.kernel.weight_2d(u / r, 1.0),
        };
        w * self.inv_norm / r
    }
}

/// Beams are cut into pieces this many widths long. Shorter pieces have tighter boxes (a
/// camera ray visits fewer pieces it does not cross), longer ones make a smaller BVH with
/// fewer nodes to visit; measured on the foggy Cornell box (ppb, 128 x 128, two passes):
/// 1, 2, 4, 8, 16, 32 widths and unsplit beams took 18.8, 9.9, 9.0, 5.5, 3.3, 3.6 and 8.9 s.
/// Measured again with core's wide traversal (instructions, the same render): 8, 12, 16, 20,
/// 24, 32 widths 3.38, 3.16, 3.09, 3.10, 3.14, 3.25 G; pieces shortened for diagonal beams
/// (whose boxes are loosest: length scaled by (0.64 / sum_{i<j} |d_i d_j|)^(1/2)) 3 % more.
pub const PIECE_WIDTHS: f32 = 16.0;

/// How far a piece's box reaches past its segment along each axis: the camera points a piece
/// accepts lie within r of the segment and perpendicular to it (the closest point on the beam
/// lies within the piece), a disc of radius r around each point of the segment, whose extent
/// along axis i is r sqrt(1 - w_i^2). Tighter than r on every axis (no reach at all along the
/// beam's axis for an axis-aligned beam), so a camera ray crosses fewer boxes for the same
/// beams. A margin of 1e-3 r, and a few ulps of the piece's coordinates (`scale`: its
/// largest), keeps rounding in the crossing test from losing a crossing at a box's face.
#[inline]
fn piece_grow(dir: Vec3, r: f32, scale: f32) -> Vec3 {
    let perp = (Vec3::ONE - dir * dir).max(Vec3::ZERO);
    perp.sqrt() * r + Vec3::splat(1e-3 * r + 8.0 * f32::EPSILON * scale)
}

/// A piece of a beam, as the BVH holds it, with what the crossing test needs of its beam
/// (so that a piece a camera ray only passes near costs no look-up of the beam).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Piece {
    pub(crate) origin: Vec3,
    pub(crate) dir: Vec3,
    pub(crate) t0: f32,
    pub(crate) t1: f32,
    pub(crate) beam: u32,
    pub(crate) medium: u32,
}

impl Piece {
    pub(crate) fn start(&self) -> Vec3 {
        self.origin + self.dir * self.t0
    }

    pub(crate) fn end(&self) -> Vec3 {
        self.origin + self.dir * self.t1
    }

    /// The piece's box in the BVH (`piece_grow`), with the padding core's BVH gives flat
    /// boxes (`Shape::aabb` of the flat triangle from one corner to the opposite one), and
    /// its number `id`. The traversal's callback tests the beam itself.
    pub(crate) fn bounds(&self, r: f32, id: u32) -> (Vec3, Vec3, u32) {
        let (p0, p1) = (self.start(), self.end());
        let scale = p0.abs().max(p1.abs()).max_element();
        let grow = piece_grow(self.dir, r, scale);
        let (lo, hi) = (p0.min(p1) - grow, p0.max(p1) + grow);
        let b = Shape::Triangle {
            p0: lo,
            e1: hi - lo,
            e2: Vec3::ZERO,
        }
        .aabb();
        (b.min.into(), b.max.into(), id)
    }
}

/// The photon beams of one pass, with a common width r, in a BVH.
pub struct BeamMap {
    beams: Vec<Beam>,
    /// Indexed by the BVH primitives' `object`.
    pub(crate) pieces: Vec<Piece>,
    pub(crate) bvh: TwoLevelBvh,
    radius: f32,
    /// The box around every beam's segment (empty when there is none).
    bounds: (Vec3, Vec3),
}

impl BeamMap {
    /// Builds the map of `beams` with width (kernel radius) `radius`, cutting beams into
    /// pieces of at most [`PIECE_WIDTHS`] x `radius`.
    pub fn build(beams: Vec<Beam>, radius: f32) -> BeamMap {
        let piece = PIECE_WIDTHS * radius;
        let usable = |b: &Beam| b.length > 0.0 && b.length.is_finite();
        let pieces: Vec<Piece> = beams
            .par_iter()
            .enumerate()
            .filter(|(_, b)| usable(b))
            .flat_map_iter(|(i, b)| {
                let n = (b.length / piece).ceil().clamp(1.0, 1e6) as u32;
                let step = b.length / n as f32;
                (0..n).map(move |k| {
                    let t0 = k as f32 * step;
                    let t1 = if k + 1 == n { b.length } else { t0 + step };
                    Piece {
                        origin: b.origin,
                        dir: b.dir,
                        t0,
                        t1,
                        beam: i as u32,
                        medium: b.medium,
                    }
                })
            })
            .collect();
        let empty = || (Vec3::INFINITY, Vec3::NEG_INFINITY);
        let bounds = beams
            .par_iter()
            .filter(|b| usable(b))
            .map(|b| {
                let end = b.origin + b.dir * b.length;
                (b.origin.min(end), b.origin.max(end))
            })
            .reduce(empty, |a, b| (a.0.min(b.0), a.1.max(b.1)));
        let boxes = pieces
            .par_iter()
            .enumerate()
            .map(|(id, p)| p.bounds(radius, id as u32))
            .collect();
        let bvh = TwoLevelBvh::build(boxes);
        BeamMap {
            beams,
            pieces,
            bvh,
            radius,
            bounds,
        }
    }

    /// The box around every beam's segment (lo > hi when there is no beam): camera segments
    /// that leave the scene in a medium gather up to where it ends, grown by the width.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    /// The bytes the map holds on the heap: the beams, their pieces and the pieces' BVH.
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        self.beams.capacity() * size_of::<Beam>()
            + self.pieces.capacity() * size_of::<Piece>()
            + self.bvh.heap_bytes()
    }

    pub fn len(&self) -> usize {
        self.beams.len()
    }

    pub fn is_empty(&self) -> bool {
        self.beams.is_empty()
    }

    pub fn beams(&self) -> &[Beam] {
        &self.beams
    }

    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// The pieces the beams were cut into.
    pub fn pieces(&self) -> usize {
        self.pieces.len()
    }

    /// Whether piece `id` of medium `medium` passes within the width of the query segment
    /// `ray` from 0 to `t_end` with its closest point within the piece and the segment: the
    /// crossing, if so. The one test of a candidate piece, wherever the candidates come from
    /// (the BVH, or the screen's bins for camera rays: `screen`), so that both accept the same.
    #[inline]
    pub(crate) fn cross(&self, id: u32, ray: &Ray, t_end: f32, medium: u32) -> Option<Crossing> {
        let r = self.radius;
        let piece = &self.pieces[id as usize];
        if piece.medium != medium {
            return None;
        }
        // Most pieces whose box the ray crosses pass farther than r from it: reject those by
        // the distance between the lines, |d . n| / |n| < r, before solving for the closest
        // points.
        let n = ray.dir.cross(piece.dir);
        let sin2 = n.length_squared();
        let d = piece.origin - ray.origin;
        let dn = d.dot(n);
        if dn * dn >= r * r * sin2 {
            return None;
        }
        let c = closest_approach_from(d, n, sin2, ray.dir, piece.dir)?;
        (c.u < r && c.t_b >= piece.t0 && c.t_b < piece.t1 && c.t_c >= 0.0 && c.t_c < t_end)
            .then_some(c)
    }

    /// The beam a piece belongs to.
    #[inline]
    pub(crate) fn beam_of(&self, id: u32) -> &Beam {
        &self.beams[self.pieces[id as usize].beam as usize]
    }

    /// Calls `visit(piece id, crossing)` for every piece of `bvh` (a BVH of this map's
    /// pieces' boxes) that [`BeamMap::cross`] accepts.
    pub(crate) fn traverse(
        &self,
        bvh: &TwoLevelBvh,
        ray: &Ray,
        t_end: f32,
        medium: u32,
        visit: &mut impl FnMut(u32, &Crossing),
    ) {
        bvh.visit(ray, t_end, |id| {
            if let Some(c) = self.cross(id, ray, t_end, medium) {
                visit(id, &c);
            }
        });
    }

    /// Calls `visit(beam, crossing)` for every beam of medium `medium` that passes within the
    /// width of the query segment `ray` (unit direction) from 0 to `t_end`, its closest
    /// point within the beam and the segment.
    pub fn along_ray(
        &self,
        ray: &Ray,
        t_end: f32,
        medium: u32,
        mut visit: impl FnMut(&Beam, &Crossing),
    ) {
        self.traverse(&self.bvh, ray, t_end, medium, &mut |id, c| {
            visit(self.beam_of(id), c)
        });
    }

    /// The beam x beam estimate of the in-scattering integral along `ray` from 0 to `t_end`
    /// in medium `medium` (`m`), from beams of at most `depth` scattering events (module
    /// comment). Not weighted by the throughput before `ray`.
    pub fn in_scattered(
        &self,
        scene: &Scene,
        kernel: &Kernel1d<'_>,
        ray: &Ray,
        t_end: f32,
        medium: u32,
        depth: u32,
    ) -> Rgb {
        let gather = Gather::new(self, scene, kernel, ray, medium, depth);
        let mut sum = Rgb::ZERO;
        self.traverse(&self.bvh, ray, t_end, medium, &mut |id, c| {
            gather.add(&mut sum, id, c)
        });
        sum
    }
}

/// One segment's beam x beam estimate: what each accepted crossing adds (module comment).
pub(crate) struct Gather<'a> {
    map: &'a BeamMap,
    coefficients: Coefficients<'a>,
    phase: Phase,
    kernel: &'a Kernel1d<'a>,
    ray: &'a Ray,
    depth: u32,
}

impl<'a> Gather<'a> {
    pub(crate) fn new(
        map: &'a BeamMap,
        scene: &'a Scene,
        kernel: &'a Kernel1d<'a>,
        ray: &'a Ray,
        medium: u32,
        depth: u32,
    ) -> Self {
        let m = scene.medium(medium);
        Gather {
            map,
            coefficients: Coefficients::of(m),
            phase: m.phase(),
            kernel,
            ray,
            depth,
        }
    }

    /// Adds what the crossing `c` of piece `id` contributes to `sum`.
    #[inline]
    pub(crate) fn add(&self, sum: &mut Rgb, id: u32, c: &Crossing) {
        let beam = self.map.beam_of(id);
        if beam.depth > self.depth {
            return;
        }
        let r = self.map.radius;
        *sum += self.coefficients.crossing(beam, self.ray, c)
            * phase_kernel(self.phase, self.kernel, r, beam, self.ray, c);
    }
}

/// What the estimate needs of the medium a camera segment crosses: its coefficients when they
/// are constant (core's `Medium::homogeneous`: the transmittances are exp(-sigma_t d) inline),
/// else the medium itself.
#[derive(Clone, Copy)]
enum Coefficients<'a> {
    /// The same sigma_t in every channel: one exponential a crossing (below).
    Grey {
        sigma_t: f32,
        sigma_s: Rgb,
    },
    Homogeneous {
        sigma_t: Rgb,
        sigma_s: Rgb,
    },
    General(&'a dyn Medium),
}

impl<'a> Coefficients<'a> {
    fn of(m: &'a dyn Medium) -> Self {
        match m.homogeneous() {
            Some(h) => {
                let sigma_t = h.sigma_t();
                if sigma_t.x == sigma_t.y && sigma_t.y == sigma_t.z {
                    Coefficients::Grey {
                        sigma_t: sigma_t.x,
                        sigma_s: h.sigma_s,
                    }
                } else {
                    Coefficients::Homogeneous {
                        sigma_t,
                        sigma_s: h.sigma_s,
                    }
                }
            }
            None => Coefficients::General(m),
        }
    }

    /// Phi_b W_b(t_b) sigma_s(x_c) Tr_c(t_c) of the beam crossing the query `ray` at `c`.
    #[inline]
    fn crossing(&self, beam: &Beam, ray: &Ray, c: &Crossing) -> Rgb {
        match *self {
            // With one sigma_t, a short beam's W_b = Tr_b / mean(r Tr_b) is 1 / mean(r) (its
            // transmittance cancels), and a long beam's Tr_b Tr_c is exp(-sigma_t (t_b + t_c)).
            Coefficients::Grey { sigma_t, sigma_s } => {
                let w = match beam.kind {
                    BeamKind::Short => {
                        let p = foton_core::api::average(beam.hero_r);
                        if p > 0.0 {
                            (-sigma_t * c.t_c).exp() / p
                        } else {
                            0.0
                        }
                    }
                    BeamKind::Long => (-sigma_t * (c.t_b + c.t_c)).exp(),
                };
                beam.flux * sigma_s * w
            }
            Coefficients::Homogeneous { sigma_t, sigma_s } => {
                beam.flux
                    * beam.weight_of(transmittance_homogeneous(sigma_t, c.t_b))
                    * sigma_s
                    * transmittance_homogeneous(sigma_t, c.t_c)
            }
            Coefficients::General(m) => {
                beam.flux
                    * beam.weight(m, c.t_b)
                    * m.sigma_s(ray.at(c.t_c))
                    * m.transmittance(ray, c.t_c)
            }
        }
    }
}

/// p(w_b . -w) K1(u, r) / sin(theta): the crossing's phase function and kernel.
#[inline]
fn phase_kernel(
    phase: Phase,
    kernel: &Kernel1d<'_>,
    r: f32,
    beam: &Beam,
    ray: &Ray,
    c: &Crossing,
) -> f32 {
    phase.eval(beam.dir.dot(-ray.dir)) * (kernel.weight(c.u, r) / c.sin)
}

/// The parameter `beam_type` (`short` or `long`, default short: see the integrators' docs).
pub fn read_beam_type(props: &Properties<'_>) -> Result<BeamKind> {
    Ok(
        match props.choice("beam_type", &["short", "long"], "short")? {
            "long" => BeamKind::Long,
            _ => BeamKind::Short,
        },
    )
}

/// The default beam width for `photons` photons emitted in a scene of bounding-box diagonal
/// `diagonal`. The 1-D estimate's variance falls as 1 / (photons r) and its bias grows as r^2,
/// so the mean squared error is least for r proportional to photons^(-1/5); the constant puts
/// r at 1/400 of the diagonal for 200000 photons (measured on the fog scenes: docs).
pub fn default_beam_radius(diagonal: f32, photons: u64) -> f32 {
    const C: f64 = 0.0025 * 11.486_983_549_970_35; // 200000^(1/5) = 11.487
    (C * diagonal as f64 * (photons.max(1) as f64).powf(-0.2)) as f32
}

/// Distance along `ray` to where it leaves the box (0 if it misses it).
pub fn exit_distance(ray: &Ray, (lo, hi): (Vec3, Vec3)) -> f32 {
    let inv = ray.dir.recip();
    let t0 = (lo - ray.origin) * inv;
    let t1 = (hi - ray.origin) * inv;
    let far = t0.max(t1).min_element();
    let near = t0.min(t1).max_element();
    if far < near.max(0.0) { 0.0 } else { far }
}

#[cfg(test)]
impl Beam {
    /// A short beam from `a` to `b` in medium `medium` carrying unit flux, for tests.
    pub(crate) fn unit_test(a: Vec3, b: Vec3, medium: u32) -> Beam {
        Beam {
            origin: a,
            dir: (b - a).normalize(),
            length: (b - a).length(),
            flux: Rgb::ONE,
            hero_r: Rgb::ONE,
            medium,
            depth: 1,
            kind: BeamKind::Short,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use foton_core::api::{BoxKernel, ConeKernel};

    #[test]
    fn closest_approach_of_crossing_lines() {
        // The x axis and a line along z through (2, 3, 0) at height... u = 3.
        let c = closest_approach(
            Vec3::new(2.0, 3.0, -5.0),
            Vec3::Z,
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::X,
        )
        .unwrap();
        assert!((c.t_c - 5.0).abs() < 1e-5, "{c:?}");
        assert!((c.t_b - 3.0).abs() < 1e-5, "{c:?}");
        assert!(
            (c.u - 3.0).abs() < 1e-5 && (c.sin - 1.0).abs() < 1e-6,
            "{c:?}"
        );
        assert!(closest_approach(Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::X).is_none());
    }

    #[test]
    fn rays_with_negative_zero_components_find_beams() {
        let beam = Beam {
            origin: Vec3::new(-1.0, 0.0, 0.0),
            dir: Vec3::X,
            length: 2.0,
            flux: Rgb::ONE,
            hero_r: Rgb::ONE,
            medium: 0,
            depth: 1,
            kind: BeamKind::Long,
        };
        let map = BeamMap::build(vec![beam], 0.1);
        // -Vec3::Z is (-0.0, -0.0, -1.0).
        for dir in [
            -Vec3::Z,
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(-0.0, 0.0, -1.0),
        ] {
            let mut found = 0;
            let ray = Ray::new(Vec3::new(0.2, 0.05, 1.0), dir);
            map.along_ray(&ray, 3.0, 0, |_, c| {
                found += 1;
                assert!((c.t_c - 1.0).abs() < 1e-5 && (c.t_b - 1.2).abs() < 1e-5);
            });
            assert_eq!(found, 1, "{dir:?}");
        }
    }

    /// The bytes a beam map holds per beam (docs/PERFORMANCE.md): beams across a unit box,
    /// a tenth of it wide, one piece each.
    #[test]
    fn a_beam_map_reports_bytes_per_beam() {
        let mut rng = foton_core::api::Rng::new(&[6]);
        let mut point = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        let n = 20_000;
        let beams: Vec<Beam> = (0..n)
            .map(|i| Beam::unit_test(point(), point(), i % 2))
            .collect();
        let map = BeamMap::build(beams, 0.1);
        let per_beam = map.heap_bytes() as f64 / n as f64;
        let record = std::mem::size_of::<Beam>() as f64;
        println!(
            "beam map: {per_beam:.1} bytes per beam ({} pieces), records of {record} bytes",
            map.pieces.len()
        );
        assert!(per_beam >= record, "{per_beam}");
        assert!(
            per_beam <= 2.0 * record,
            "{per_beam} bytes per {record}-byte beam"
        );
    }

    /// The BVH's traversal finds exactly the beams a loop over all of them finds (random
    /// beams cut into many pieces, a quarter of them along an axis, whose boxes reach no
    /// farther than their ends along it; random rays and segment ends, two media).
    #[test]
    fn the_bvh_finds_what_a_loop_over_every_beam_finds() {
        let mut rng = foton_core::api::Rng::new(&[5]);
        let mut point = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0;
        let beams: Vec<Beam> = (0..400)
            .map(|i| {
                let (a, mut b) = (point(), point());
                if i % 4 == 3 {
                    let axis = [Vec3::X, Vec3::Y, Vec3::Z][(i as usize / 4) % 3];
                    b = a + axis * (b - a).dot(axis);
                }
                Beam::unit_test(a, b, i % 2)
            })
            .collect();
        let r = 0.05;
        let map = BeamMap::build(beams.clone(), r);
        let mut found_total = 0;
        for _ in 0..300 {
            let (o, to) = (point(), point());
            let ray = Ray::new(o, (to - o).normalize());
            let t_end = (to - o).length();
            let mut found = Vec::new();
            map.along_ray(&ray, t_end, 0, |b, c| {
                found.push((b.origin.x.to_bits(), c.t_c))
            });
            found.sort_by_key(|f| f.0);
            let mut want = Vec::new();
            for b in beams.iter().filter(|b| b.medium == 0) {
                if let Some(c) = closest_approach(ray.origin, ray.dir, b.origin, b.dir)
                    && c.u < r
                    && (0.0..b.length).contains(&c.t_b)
                    && (0.0..t_end).contains(&c.t_c)
                {
                    want.push((b.origin.x.to_bits(), c.t_c));
                }
            }
            want.sort_by_key(|f| f.0);
            assert_eq!(found, want);
            found_total += found.len();
        }
        assert!(
            found_total > 100,
            "too few crossings to compare: {found_total}"
        );
    }

    /// A piece's box is only as large as the disc of radius r across the beam reaches (not r
    /// on every axis): camera rays passing a beam at 0.999 r, offset along the direction
    /// across the beam that reaches farthest on each axis, by either end of a piece, are all
    /// found, for beams along the axes and in random directions.
    #[test]
    fn boxes_reach_as_far_as_the_width_across_the_beam() {
        let mut rng = foton_core::api::Rng::new(&[11]);
        let mut unit = || {
            let v = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
            v.normalize()
        };
        let r = 0.05;
        let mut dirs = vec![
            Vec3::X,
            Vec3::Y,
            -Vec3::Z,
            Vec3::new(1.0, 1.0, 0.0).normalize(),
        ];
        dirs.extend((0..20).map(|_| unit()));
        for (i, dir) in dirs.into_iter().enumerate() {
            let origin = Vec3::new(0.3, -1.2, 2.1) + dir * 0.01;
            let length = 2.5;
            let beam = Beam {
                origin,
                dir,
                length,
                flux: Rgb::ONE,
                hero_r: Rgb::ONE,
                medium: 0,
                depth: 1,
                kind: BeamKind::Short,
            };
            let map = BeamMap::build(vec![beam], r);
            let piece = length / (length / (PIECE_WIDTHS * r)).ceil();
            for axis in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z] {
                let across = axis - dir * axis.dot(dir);
                if across.length() < 1e-3 {
                    continue; // the beam runs along this axis: no offset reaches along it
                }
                let offset = across.normalize() * (0.999 * r);
                // The ray crosses the beam at right angles to the offset.
                let w = offset.cross(dir).normalize();
                for t_b in [1e-4, piece - 1e-4, piece + 1e-4, length - 1e-4] {
                    let p = origin + dir * t_b + offset;
                    let ray = Ray::new(p - w * 1.0, w);
                    let mut found = 0;
                    map.along_ray(&ray, 2.0, 0, |_, c| {
                        found += 1;
                        assert!((c.u - 0.999 * r).abs() < 1e-4, "{c:?}");
                    });
                    assert_eq!(
                        found, 1,
                        "beam {i} along {dir:?}, offset {offset:?}, t_b {t_b}"
                    );
                }
            }
        }
    }

    #[test]
    fn kernel_1d_integrates_to_one() {
        for k in [
            NormalizedKernel::new(Box::new(BoxKernel)).unwrap(),
            NormalizedKernel::new(Box::new(ConeKernel { c: 1.0 })).unwrap(),
        ] {
            let k1 = Kernel1d::new(&k);
            let r = 0.3;
            let n = 20000;
            let sum: f64 = (0..n)
                .map(|i| {
                    let u = -r + 2.0 * r * (i as f32 + 0.5) / n as f32;
                    k1.weight(u.abs(), r) as f64 * 2.0 * r as f64 / n as f64
                })
                .sum();
            assert!((sum - 1.0).abs() < 1e-3, "{}: {sum}", k.name());
        }
        let b = NormalizedKernel::new(Box::new(BoxKernel)).unwrap();
        assert!((Kernel1d::new(&b).weight(0.1, 0.5) - 1.0).abs() < 1e-4);
    }
}
