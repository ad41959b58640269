//! Where photons start: the lights, and the media that emit (pbrt-v4's `Le`).
//!
//! An emitting medium radiates sigma_a Le per unit volume and solid angle, the same in every
//! direction: its power is 4 pi times the integral of sigma_a Le over the region it fills.
//! A photon from it starts at a point p drawn in a box around that region (the shapes that
//! border the medium, `Scene::medium_region`) from a piecewise-constant density over a
//! lattice of cells, each cell weighted by the largest sigma_a Le at its corners (and never
//! less than a thousandth of the largest cell, so that emission between the corners is drawn
//! too), in a direction uniform over the sphere, and carries
//!
//! ```text
//! Phi = 4 pi sigma_a(p) Le(p) / (pdf(p) P(source) N)
//! ```
//!
//! (zero where the medium at p is another: the box is larger than the region). Sources are
//! chosen in proportion to power: the lights' total, and each medium's power estimated from
//! the mean over its cells' corners; the estimate changes only the noise. (A medium whose
//! sigma_a Le is zero at every corner of its lattice, an emitter smaller than a cell between
//! them, emits no photons.)

use foton_core::api::{Distribution1D, Error, LightType, Result, Rgb, Scene, uniform_sphere};
use glam::{Vec2, Vec3};

/// Cells per axis of an emitting medium's lattice.
const CELLS: usize = 16;

/// The photon sources of a scene: the lights and its emitting media.
pub struct Sources {
    /// The medium each light emits into ([`Scene::emission_media`]).
    pub light_media: Vec<Option<u32>>,
    /// The probability of starting from a light (1 without emitting media).
    light_fraction: f32,
    media: Vec<VolumeSource>,
    /// Among the media, by power.
    pick: Distribution1D,
}

/// An emitting medium as a photon source.
struct VolumeSource {
    medium: u32,
    lo: Vec3,
    size: Vec3,
    cells: Distribution1D,
}

/// Where a photon starts and what it carries.
pub struct Start {
    pub origin: Vec3,
    /// The surface normal at the origin (zero in a medium or for a point light).
    pub n: Vec3,
    pub dir: Vec3,
    /// Its flux is `power / (pdf x photons emitted)`: the power the sample stands for (a
    /// light's `EmittedRay::flux`, or 4 pi sigma_a Le) and the probability (density) of
    /// drawing it, the source's choice included.
    pub power: Rgb,
    pub pdf: f32,
    /// The medium it starts in.
    pub medium: Option<u32>,
    /// Whether it leaves an emitting medium.
    pub from_medium: bool,
    /// Whether next-event estimation samples its source: not an emitting medium nor a
    /// collimated beam, whose light's first bounce the estimators' direct lighting never
    /// reaches, so that the photons must render it.
    pub nee: bool,
}

impl Sources {
    pub fn new(scene: &Scene) -> Result<Sources> {
        let light_media = scene.emission_media()?;
        let mut media = Vec::new();
        let mut powers = Vec::new();
        if scene.emissive_medium().is_some() {
            for (id, named) in scene.media().iter().enumerate() {
                let m = named.value.as_ref();
                if !m.is_emissive() {
                    continue;
                }
                let Some((lo, hi)) = scene.medium_region(id as u32) else {
                    return Err(Error::Usage(format!(
                        "{}: medium {:?} emits light and fills the space around the shapes: the \
                         photon mappers emit photons from bounded media only (use `path` or `bdpt`)",
                        scene.file().display(),
                        named.name
                    )));
                };
                let size = (hi - lo).max(Vec3::splat(1e-6));
                let n = CELLS + 1;
                let corner = |i: usize, j: usize, k: usize| {
                    let p = lo + size * Vec3::new(i as f32, j as f32, k as f32) / CELLS as f32;
                    (m.sigma_a(p) * m.emission(p)).max_element().max(0.0)
                };
                let mut lattice = vec![0.0f32; n * n * n];
                for k in 0..n {
                    for j in 0..n {
                        for i in 0..n {
                            lattice[(k * n + j) * n + i] = corner(i, j, k);
                        }
                    }
                }
                let mut weights = Vec::with_capacity(CELLS.pow(3));
                let mut mean = 0.0f64;
                for k in 0..CELLS {
                    for j in 0..CELLS {
                        for i in 0..CELLS {
                            let (mut max, mut sum) = (0.0f32, 0.0f32);
                            for c in 0..8 {
                                let v = lattice
                                    [((k + (c >> 2)) * n + j + ((c >> 1) & 1)) * n + i + (c & 1)];
                                max = max.max(v);
                                sum += v;
                            }
                            weights.push(max);
                            mean += sum as f64 / 8.0;
                        }
                    }
                }
                let largest = weights.iter().copied().fold(0.0, f32::max);
                if largest <= 0.0 {
                    continue;
                }
                weights.iter_mut().for_each(|w| *w = w.max(1e-3 * largest));
                let volume = size.x as f64 * size.y as f64 * size.z as f64;
                let power = 4.0 * std::f64::consts::PI * mean / CELLS.pow(3) as f64 * volume;
                media.push(VolumeSource {
                    medium: id as u32,
                    lo,
                    size,
                    cells: Distribution1D::new(&weights),
                });
                powers.push(power.max(1e-30) as f32);
            }
        }
        let media_power: f32 = powers.iter().sum();
        let light_power = scene.total_power().max_element();
        let light_fraction = if media.is_empty() {
            1.0
        } else if scene.sample_light(0.5).is_none() {
            0.0
        } else {
            light_power / (light_power + media_power)
        };
        Ok(Sources {
            light_media,
            light_fraction,
            media,
            pick: Distribution1D::new(&powers),
        })
    }

    /// Samples a photon's start: `u_source` chooses the source, `u_pos`, `u_dir` and `uc` are
    /// the light's sample (`Light::sample_emission`), or, in a medium, choose the cell and the
    /// point in it (`uc` and `u_pos`) and the direction (`u_dir`). None: nothing emits.
    pub fn sample(
        &self,
        scene: &Scene,
        u_source: f32,
        u_pos: Vec2,
        u_dir: Vec2,
        uc: f32,
    ) -> Option<Start> {
        if u_source < self.light_fraction {
            // Without emitting media the fraction is 1: u_source itself, the light's pmf as is.
            let (light_id, pmf) = scene.sample_light(u_source / self.light_fraction)?;
            let emitted = scene.lights()[light_id].sample_emission(u_pos, u_dir, uc);
            return Some(Start {
                origin: emitted.origin,
                n: emitted.n,
                dir: emitted.dir,
                power: emitted.flux,
                pdf: pmf * self.light_fraction,
                medium: self.light_media[light_id],
                from_medium: false,
                nee: scene.lights()[light_id].light_type() != LightType::DeltaBeam,
            });
        }
        let u = ((u_source - self.light_fraction) / (1.0 - self.light_fraction)).min(0.99999994);
        let (j, pick) = self.pick.sample(u);
        let source = &self.media[j];
        // The cell from `uc`, what is left of it placing the point along x.
        let (x, density, cell) = source.cells.sample_continuous(uc);
        let fx = (x * (CELLS * CELLS * CELLS) as f32 - cell as f32).clamp(0.0, 1.0);
        let (ci, cj, ck) = (cell % CELLS, (cell / CELLS) % CELLS, cell / (CELLS * CELLS));
        let local = (Vec3::new(ci as f32, cj as f32, ck as f32) + Vec3::new(fx, u_pos.x, u_pos.y))
            / CELLS as f32;
        let origin = source.lo + source.size * local;
        // `density` is per unit of the box's volume.
        let pdf = density / (source.size.x * source.size.y * source.size.z);
        let m = scene.medium(source.medium);
        let inside = scene.medium_at(origin).ok().flatten() == Some(source.medium);
        let power = if inside {
            4.0 * std::f32::consts::PI * m.sigma_a(origin) * m.emission(origin)
        } else {
            Rgb::ZERO
        };
        Some(Start {
            origin,
            n: Vec3::ZERO,
            dir: uniform_sphere(u_dir),
            power,
            pdf: pdf * pick * (1.0 - self.light_fraction),
            medium: Some(source.medium),
            from_medium: true,
            nee: false,
        })
    }
}
