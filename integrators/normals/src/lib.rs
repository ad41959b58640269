//! # `normals`: surface normals as colours
//!
//! The minimal example integrator plugin of docs/plugins.md, and a quick look at a scene's
//! geometry and orientation. Each camera ray is followed to the first surface whose material
//! is not `null` (null boundaries are crossed); the pixel is the unit shading normal `n` there
//! (the geometric one, but on smooth meshes, where it is interpolated) mapped to a colour, `n * 0.5 + 0.5` (x to red, y to green, z to blue), and black when the
//! ray hits nothing. The walk is core's `foton_core::api::first_surface` (the crossing loop
//! every integrator shares): past `MAX_NULL_CROSSINGS` null boundaries in a row the ray is
//! given up, and the pixel is black.
//!
//! | parameter        | type    | meaning                                                | default |
//! |------------------|---------|--------------------------------------------------------|---------|
//! | `flip_to_camera` | boolean | flip each normal to face the camera (the ray's origin) | false   |
//!
//! Without the flip, the normal keeps the shape's own orientation (outward for spheres,
//! normalize(u x v) for quads, normalize(e1 x e2) for mesh triangles), which is also the side
//! an emissive shape emits on: a surface seen from its back shows the colour of the opposite
//! direction. `[render] spp` samples are averaged per pixel (silhouettes are anti-aliased);
//! `max_depth`, materials, lights and media play no part. The values are written as they are:
//! exactly to an EXR, sRGB-encoded to a PNG like any other linear value.

use foton_core::api::{
    Film, Integrator, Parameter, Properties, Ray, RenderContext, Result, Rgb, Scene, first_surface,
    render_pixels,
};

pub struct Normals {
    flip_to_camera: bool,
}

impl Normals {
    pub fn new(flip_to_camera: bool) -> Self {
        Normals { flip_to_camera }
    }

    /// The colour seen along a camera ray; adds the rays traced to `rays` (statistics).
    pub fn shade(&self, scene: &Scene, ray: Ray, rays: &mut u64) -> Rgb {
        // Core's walk crosses null boundaries (and gives up, black, past its crossing limit).
        let Some((hit, _)) = first_surface(scene, ray, scene.camera_medium(), rays) else {
            return Rgb::ZERO;
        };
        // The shading normal (interpolated on smooth meshes), as a renderer's normal pass.
        let mut n = scene.surface(&hit).ns;
        if self.flip_to_camera && hit.ng.dot(ray.dir) > 0.0 {
            n = -n;
        }
        n * 0.5 + Rgb::splat(0.5)
    }
}

impl Integrator for Normals {
    fn render(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Film> {
        render_pixels(scene, ctx, |ray, _sampler, rays| {
            self.shade(scene, *ray, rays)
        })
    }

    fn name(&self) -> &str {
        "normals"
    }

    fn parameters(&self) -> Vec<Parameter> {
        vec![Parameter::bool("flip_to_camera", self.flip_to_camera)]
    }
}

/// Reads the parameters (see the table above) from the scene's `[integrators.normals]` table.
pub fn create(props: &Properties<'_>, _scene: &Scene) -> Result<Box<dyn Integrator>> {
    let flip_to_camera = props.bool("flip_to_camera", false)?;
    Ok(Box::new(Normals::new(flip_to_camera)))
}

foton_core::api::declare_integrator!("normals", "surface normals as colours (example)", create);
