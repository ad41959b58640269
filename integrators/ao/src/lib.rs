//! # `ao`: ambient occlusion
//!
//! A geometry pass, not an estimate of light: each pixel is the fraction of the hemisphere
//! above the first surface its camera rays meet that is open, weighted by the cosine,
//!
//! ```text
//! A(p) = 1/pi ∫ V(p, w) |n · w| dw,
//! ```
//!
//! V being 1 where a ray from p along w meets nothing within `max_distance`. It is pbrt-v4's
//! `ambientocclusion` integrator: the hemisphere is the geometric normal's, turned towards the
//! camera (a surface seen from its back is occluded on that side); null boundaries are crossed
//! on the way from the camera (they have no surface to occlude) but stop the occlusion rays,
//! as every other surface does (pbrt-v4's `IntersectP` meets medium interfaces too); a pixel
//! whose rays meet nothing is black; materials, lights and media play no part. An open
//! hemisphere is 1 in every channel (pbrt-v4 returns its colour space's illuminant at
//! luminance 1, white in sRGB).
//!
//! | parameter      | type    | meaning                                                      | default   |
//! |----------------|---------|--------------------------------------------------------------|-----------|
//! | `cosine`       | boolean | directions drawn by the cosine (else uniformly, weighted by 2 cos) | true |
//! | `max_distance` | number  | length of the occlusion rays (`inf`: unbounded)               | inf       |
//!
//! Both ways of drawing directions estimate the same A(p): the cosine's estimate is V itself
//! (0 or 1), the uniform one's 2 V cos θ, noisier.

use foton_core::api::Vec2;
use foton_core::api::{
    Film, Integrator, Parameter, Properties, Ray, RenderContext, Result, Rgb, Scene,
    cosine_hemisphere, first_surface, offset_origin, render_pixels, to_world, uniform_hemisphere,
};

pub struct AmbientOcclusion {
    cosine: bool,
    max_distance: f32,
}

impl AmbientOcclusion {
    pub fn new(cosine: bool, max_distance: f32) -> Self {
        AmbientOcclusion {
            cosine,
            max_distance,
        }
    }

    /// One estimate of A at the first surface along a camera ray, drawn with `u`; adds the
    /// rays traced to `rays`.
    pub fn shade(&self, scene: &Scene, ray: Ray, u: Vec2, rays: &mut u64) -> Rgb {
        let Some((hit, _)) = first_surface(scene, ray, scene.camera_medium(), rays) else {
            return Rgb::ZERO;
        };
        let n = if hit.ng.dot(ray.dir) > 0.0 {
            -hit.ng
        } else {
            hit.ng
        };
        // pdf cos/pi against the integrand V cos/pi: the estimate is V. Uniformly (pdf
        // 1/(2 pi)) it is 2 V cos.
        let (local, weight) = if self.cosine {
            (cosine_hemisphere(u), 1.0)
        } else {
            let w = uniform_hemisphere(u);
            (w, 2.0 * w.z)
        };
        if weight <= 0.0 {
            return Rgb::ZERO;
        }
        let wi = to_world(local, n);
        let shadow = Ray::new(offset_origin(hit.p, n, wi), wi);
        *rays += 1;
        if scene.intersect(&shadow, self.max_distance).is_some() {
            Rgb::ZERO
        } else {
            Rgb::splat(weight)
        }
    }
}

impl Integrator for AmbientOcclusion {
    fn render(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Film> {
        render_pixels(scene, ctx, |ray, sampler, rays| {
            self.shade(scene, *ray, sampler.next_2d(), rays)
        })
    }

    fn name(&self) -> &str {
        "ao"
    }

    fn parameters(&self) -> Vec<Parameter> {
        vec![
            Parameter::bool("cosine", self.cosine),
            Parameter::float("max_distance", self.max_distance),
        ]
    }
}

/// Reads the parameters (see the table above) from the scene's `[integrators.ao]` table.
pub fn create(props: &Properties<'_>, _scene: &Scene) -> Result<Box<dyn Integrator>> {
    let cosine = props.bool("cosine", true)?;
    let max_distance = props.f32_or_inf("max_distance", f32::INFINITY)?;
    if max_distance.is_nan() || max_distance <= 0.0 {
        return Err(props.error(
            "max_distance",
            format!("expected a positive length or inf, found {max_distance}"),
        ));
    }
    Ok(Box::new(AmbientOcclusion::new(cosine, max_distance)))
}

foton_core::api::declare_integrator!(
    "ao",
    "ambient occlusion: the open fraction of the hemisphere, cosine-weighted",
    create
);
