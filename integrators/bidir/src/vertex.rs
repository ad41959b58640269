//! The subpath vertex: where a camera or light subpath can be connected or merged, and what
//! scatters there.

use crate::mis::Running;
use foton_core::api::{Bsdf, Hit, Phase, Rgb, Scene, Vec3};

/// A vertex of a subpath where it can be connected: a surface whose BSDF is not a delta, or a
/// scattering event in a medium.
#[derive(Clone, Copy, Debug)]
pub struct Vertex {
    pub p: Vec3,
    pub at: At,
    /// The medium the subpath arrived in (None: vacuum).
    pub medium: Option<u32>,
    /// Unit direction back along the subpath (towards the camera, or where the light came from).
    pub wo: Vec3,
    /// Throughput of the subpath up to this vertex (its own scattering not included): radiance
    /// weights from the camera, flux over pdfs from the light.
    pub beta: Rgb,
    pub running: Running,
    /// Segments from the subpath's first vertex (the pinhole or the light).
    pub length: u32,
}

/// What scatters at a vertex.
#[derive(Clone, Copy, Debug)]
pub enum At {
    Surface { hit: Hit, bsdf: Bsdf },
    Medium { phase: Phase },
}

impl Vertex {
    /// The normal a shadow ray's end is offset along (zero in a medium).
    #[inline]
    pub fn ng(&self) -> Vec3 {
        match &self.at {
            At::Surface { hit, .. } => hit.ng,
            At::Medium { .. } => Vec3::ZERO,
        }
    }

    /// The cosine that turns a solid-angle density of reaching this vertex along `w` into a
    /// density per unit area (per unit volume in a medium: 1).
    #[inline]
    pub fn cos(&self, w: Vec3) -> f32 {
        match &self.at {
            At::Surface { hit, .. } => hit.ng.dot(w).abs(),
            At::Medium { .. } => 1.0,
        }
    }

    /// The solid-angle density of sampling `wi` given `wo` here.
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match &self.at {
            At::Surface { bsdf, .. } => bsdf.pdf(wo, wi),
            At::Medium { phase } => phase.eval(-wo.dot(wi)),
        }
    }

    /// What a camera vertex scatters from `w` towards the camera: f(wo, w) |w.ns| at a
    /// surface, the phase function in a medium.
    #[inline]
    pub fn f_camera(&self, w: Vec3) -> Rgb {
        match &self.at {
            At::Surface { bsdf, .. } => bsdf.eval(self.wo, w),
            At::Medium { phase } => Rgb::splat(phase.eval(-self.wo.dot(w))),
        }
    }

    /// What a light vertex sends along `w` (unit, away from it), per unit of its throughput:
    /// at a surface f(w, wo) |w.ng| with the shading-normal correction of importance transport
    /// (Veach 1997, section 5.3), f |wo.ns| |w.ng| / |wo.ng|, which `Bsdf::eval` (carrying
    /// |wo.ns|) times |w.ng| / |wo.ng| gives; in a medium the phase function.
    #[inline]
    pub fn f_light(&self, w: Vec3) -> Rgb {
        match &self.at {
            At::Surface { hit, bsdf } => {
                let cos_wo = hit.ng.dot(self.wo).abs();
                if cos_wo == 0.0 {
                    return Rgb::ZERO;
                }
                bsdf.eval(w, self.wo) * (hit.ng.dot(w).abs() / cos_wo)
            }
            At::Medium { phase } => Rgb::splat(phase.eval(-self.wo.dot(w))),
        }
    }

    /// The medium a ray leaving the vertex along `w` travels in.
    #[inline]
    pub fn medium_towards(&self, scene: &Scene, w: Vec3) -> Option<u32> {
        match &self.at {
            At::Surface { hit, .. } => scene.medium_after(hit, w, self.medium),
            At::Medium { .. } => self.medium,
        }
    }
}
