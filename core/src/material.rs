//! Materials and their BSDFs. All work in world space around the geometric normal `ng`
//! (the shape's own orientation); diffuse and mirror surfaces are two-sided.

use crate::Rgb;
use crate::sampling::{cosine_hemisphere, to_world};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Lambertian: f = reflectance / pi.
    Diffuse { reflectance: Rgb },
    /// Perfect specular reflection scaled by `reflectance`.
    Mirror { reflectance: Rgb },
    /// Smooth dielectric interface with Fresnel reflection and refraction; `ior` is the index
    /// of the side the normal points away from (inside), relative to the outside.
    Dielectric { ior: f32 },
    /// A thin sheet of glass (Mitsuba's `thindielectric`): light is reflected or passes
    /// straight through, with the Fresnel reflectance of the sheet's two faces and their
    /// interreflections, R' = 2R / (1 + R). It bounds no volume.
    ThinDielectric { ior: f32 },
    /// An invisible boundary (of a medium): rays cross it without scattering.
    Null,
}

/// Which quantity a path carries: radiance (camera paths) or importance/flux (photon paths).
/// It matters at refraction, where radiance is scaled by 1/eta^2 and flux is not (Veach 1997,
/// non-symmetric scattering due to refraction).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransportMode {
    Radiance,
    Importance,
}

#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    pub wi: Vec3,
    /// f |cos theta_i| / pdf: what the path throughput is multiplied by.
    pub weight: Rgb,
    /// For delta lobes the probability of having chosen that lobe.
    pub pdf: f32,
    pub delta: bool,
}

/// Unpolarised Fresnel reflectance of a dielectric interface. `cos_i` >= 0 is the cosine on
/// the incident side, `eta` = n_transmitted / n_incident.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0; // total internal reflection
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

#[inline]
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    2.0 * wo.dot(n) * n - wo
}

/// Refracts `wo` (pointing away from the surface, on the side of `n`) through the interface;
/// `eta` = n_transmitted / n_incident. None on total internal reflection.
#[inline]
pub fn refract(wo: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = wo.dot(n);
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-wo / eta + (cos_i / eta - cos_t) * n).normalize())
}

impl Material {
    /// True when the BSDF is a sum of Dirac deltas (mirror, smooth glass): it cannot be
    /// evaluated for a given pair of directions, only sampled. Photons are never stored there.
    pub fn is_delta(&self) -> bool {
        matches!(
            self,
            Material::Mirror { .. } | Material::Dielectric { .. } | Material::ThinDielectric { .. }
        )
    }

    pub fn is_null(&self) -> bool {
        matches!(self, Material::Null)
    }

    /// BSDF value f(wo, wi) (without the cosine). Zero for delta materials.
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3, ng: Vec3) -> Rgb {
        match *self {
            Material::Diffuse { reflectance } => {
                if wo.dot(ng) * wi.dot(ng) > 0.0 {
                    reflectance * FRAC_1_PI
                } else {
                    Rgb::ZERO
                }
            }
            _ => Rgb::ZERO,
        }
    }

    /// Solid-angle pdf with which `sample` produces wi (zero for delta materials).
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3, ng: Vec3) -> f32 {
        match *self {
            Material::Diffuse { .. } if wo.dot(ng) * wi.dot(ng) > 0.0 => {
                wi.dot(ng).abs() * FRAC_1_PI
            }
            _ => 0.0,
        }
    }

    /// Samples an incident direction for the outgoing direction `wo`. `u` chooses a direction
    /// within a lobe, `uc` chooses between lobes (reflection or refraction).
    #[inline]
    pub fn sample(
        &self,
        wo: Vec3,
        ng: Vec3,
        u: Vec2,
        uc: f32,
        mode: TransportMode,
    ) -> Option<BsdfSample> {
        let cos_o = wo.dot(ng);
        if cos_o == 0.0 {
            return None;
        }
        let n = if cos_o > 0.0 { ng } else { -ng };
        match *self {
            Material::Diffuse { reflectance } => {
                let local = cosine_hemisphere(u);
                if local.z <= 0.0 {
                    return None;
                }
                Some(BsdfSample {
                    wi: to_world(local, n),
                    weight: reflectance,
                    pdf: local.z * FRAC_1_PI,
                    delta: false,
                })
            }
            Material::Mirror { reflectance } => Some(BsdfSample {
                wi: reflect(wo, n),
                weight: reflectance,
                pdf: 1.0,
                delta: true,
            }),
            Material::Dielectric { ior } => {
                let eta = if cos_o > 0.0 { ior } else { 1.0 / ior };
                let f = fresnel_dielectric(cos_o.abs(), eta);
                if uc < f {
                    return Some(BsdfSample {
                        wi: reflect(wo, n),
                        weight: Rgb::ONE,
                        pdf: f,
                        delta: true,
                    });
                }
                let wi = refract(wo, n, eta)?;
                let scale = match mode {
                    TransportMode::Radiance => 1.0 / (eta * eta),
                    TransportMode::Importance => 1.0,
                };
                Some(BsdfSample {
                    wi,
                    weight: Rgb::splat(scale),
                    pdf: 1.0 - f,
                    delta: true,
                })
            }
            Material::ThinDielectric { ior } => {
                // Air-glass-air: the same reflectance from either side; the infinite series of
                // reflections inside the sheet sums to R' = R + T^2 R / (1 - R^2) = 2R / (1 + R).
                let r = fresnel_dielectric(cos_o.abs(), ior);
                let r = 2.0 * r / (1.0 + r);
                if uc < r {
                    return Some(BsdfSample {
                        wi: reflect(wo, n),
                        weight: Rgb::ONE,
                        pdf: r,
                        delta: true,
                    });
                }
                // Straight through: the two refractions undo each other (no 1/eta^2 either).
                Some(BsdfSample {
                    wi: -wo,
                    weight: Rgb::ONE,
                    pdf: 1.0 - r,
                    delta: true,
                })
            }
            Material::Null => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_normal_incidence() {
        let f = fresnel_dielectric(1.0, 1.5);
        assert!((f - 0.04).abs() < 1e-6);
        assert_eq!(fresnel_dielectric(0.1, 1.0 / 1.5), 1.0);
    }

    #[test]
    fn refraction_obeys_snell() {
        let n = Vec3::Z;
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let wi = refract(wo, n, 1.5).unwrap();
        let sin_i = 0.6;
        let sin_t = (1.0 - wi.z * wi.z).sqrt();
        assert!((sin_i - 1.5 * sin_t).abs() < 1e-5);
        assert!(wi.z < 0.0 && wi.x < 0.0);
    }
}
