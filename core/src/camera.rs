//! A perspective camera with a vertical field of view, a pinhole or a thin lens, or an
//! orthographic camera, and their importance for estimators that trace paths from the lights
//! (pbrt-v4's `PerspectiveCamera::We`, `PDF_We`, `SampleWi`).
//!
//! **Orthographic.** Camera rays are parallel, along the optical axis, from the points of a
//! rectangle through the camera's position perpendicular to it (the view, `view_height`
//! world units tall). Its importance is a delta in direction and uniform in position,
//! We = delta(w - forward) / A (A the view's area): a point p is seen along -forward only,
//! from the point of the view it projects to, and the density per unit area at p of camera
//! rays reaching it is |cos theta_p| / A, with no distance fall-off (as light arriving from a
//! directional light).
//!
//! **Thin lens.** With a lens of radius r focused at distance f (along the optical axis),
//! a camera ray starts at a uniform point of the lens disc and goes through the point of the
//! plane of focus that the pinhole's ray through the same film point reaches: points on that
//! plane are sharp, others blur. A point projects onto the film through the lens's centre
//! from where the ray crosses the plane of focus.
//!
//! **Importance.** The importance is normalised over the whole image, as pbrt-v4's is: a
//! camera ray's direction w, at angle theta from the optical axis, has the density
//! `pdf_dir = 1 / (A cos^3 theta)` (A the area of the image on the plane at distance 1 in
//! front of the pinhole: a uniform point of that plane, seen from the pinhole) and the
//! importance `We = 1 / (A cos^4 theta)`, so that `We cos theta / pdf_dir = 1`. A light path
//! vertex seen by the camera then contributes `We cos theta / d^2` times what it sends towards
//! the pinhole to the point of the image it projects to; summed over one light path per camera
//! sample, and divided by the camera samples per pixel, that is the image
//! ([`crate::film::Film`]'s splats).
//!
//! **Meters.** Mitsuba's `radiancemeter` and `irradiancemeter` measure instead of imaging,
//! on a film of one pixel ([`Meter`]). Light paths cannot reach them (their `we` is None): only
//! integrators that trace from the camera render them ([`crate::integrator::Integrator::renders_meters`]).

use crate::geometry::{Ray, Shape, offset_origin};
use crate::sampling::{Distribution1D, cosine_hemisphere, to_world};
use glam::{Vec2, Vec3};
use std::sync::Arc;

/// A sensor that measures a single value (a film of one pixel).
#[derive(Clone, Debug)]
pub enum Meter {
    /// The radiance arriving at the camera's position from along its optical axis: every
    /// ray is the one from the position along the axis (Mitsuba's `radiancemeter`).
    Radiance,
    /// The irradiance averaged over a surface (Mitsuba's `irradiancemeter`): rays from
    /// uniform points of the shapes (by area), cosine-distributed about the normal there,
    /// each weighted by pi, so that the mean is (1/A) int_A int_H L cos dw dA.
    Irradiance {
        shapes: Vec<Shape>,
        by_area: Distribution1D,
    },
}

/// A connection from a point to the camera ([`Camera::sample_wi`]).
#[derive(Clone, Copy, Debug)]
pub struct CameraSample {
    /// The point on the lens (the pinhole's position without one).
    pub p: Vec3,
    /// Unit direction from the point towards `p`.
    pub wi: Vec3,
    /// Distance from the point to `p`.
    pub dist: f32,
    /// The camera's importance We of the ray from `p` through the point.
    pub we: f32,
    /// The solid-angle density at the point of having sampled this direction:
    /// dist^2 / (cos theta  lens area), a pinhole's lens area taken as one (as pbrt-v4's is).
    pub pdf: f32,
    /// Where on the film the point lands (pixel units, (0, 0) the top-left corner).
    pub film: Vec2,
    /// cos theta: between the optical axis and the ray from `p`.
    pub cos: f32,
}

#[derive(Clone, Debug)]
pub struct Camera {
    pub position: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    /// tan(fov/2): half the height of the image plane at distance 1; orthographic: half the
    /// view's height (world units).
    tan_half: f32,
    /// The image's centre on the plane at distance 1 (orthographic: on the view's plane),
    /// along `right` and `up`: zero unless the window is off the optical axis
    /// ([`Camera::with_shift`]).
    shift: Vec2,
    /// Parallel rays along `forward` ([`Camera::orthographic`]).
    orthographic: bool,
    width: u32,
    height: u32,
    /// The lens's radius: zero for a pinhole.
    lens_radius: f32,
    /// Distance from the lens to the plane of focus, along the optical axis.
    focal_distance: f32,
    /// A meter instead of an image ([`Meter`]); None for a camera.
    meter: Option<Arc<Meter>>,
}

impl Camera {
    /// `fov_degrees` is the vertical field of view; `up` need not be orthogonal to the view.
    pub fn new(
        position: Vec3,
        look_at: Vec3,
        up: Vec3,
        fov_degrees: f32,
        width: u32,
        height: u32,
    ) -> Camera {
        let forward = (look_at - position).normalize();
        let right = forward.cross(up).normalize();
        let up = right.cross(forward);
        Camera {
            position,
            forward,
            right,
            up,
            tan_half: (fov_degrees.to_radians() * 0.5).tan(),
            shift: Vec2::ZERO,
            orthographic: false,
            width,
            height,
            lens_radius: 0.0,
            focal_distance: 1.0,
            meter: None,
        }
    }

    /// A radiance meter at `position` looking towards `look_at` (Mitsuba's
    /// `radiancemeter`): a film of one pixel holding the radiance arriving along that ray.
    pub fn radiance_meter(position: Vec3, look_at: Vec3, up: Vec3) -> Camera {
        let mut camera = Camera::new(position, look_at, up, 1.0, 1, 1);
        camera.meter = Some(Arc::new(Meter::Radiance));
        camera
    }

    /// An irradiance meter over `shapes` (Mitsuba's `irradiancemeter`): a film of one pixel
    /// holding the irradiance on their normal side, averaged over their area. None if the
    /// shapes have no area.
    pub fn irradiance_meter(shapes: Vec<Shape>) -> Option<Camera> {
        let areas: Vec<f32> = shapes.iter().map(Shape::area).collect();
        let total: f32 = areas.iter().sum();
        if total.is_nan() || total <= 0.0 {
            return None;
        }
        // Where its rays start, for what asks where the camera is (the medium around it).
        let (p, n) = shapes[0].sample_area(Vec2::splat(0.5));
        let position = offset_origin(p, n, n);
        let up = if n.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
        let mut camera = Camera::new(position, position + n, up, 1.0, 1, 1);
        camera.meter = Some(Arc::new(Meter::Irradiance {
            by_area: Distribution1D::new(&areas),
            shapes,
        }));
        Some(camera)
    }

    /// The meter this sensor is, if it is one.
    #[inline]
    pub fn meter(&self) -> Option<&Meter> {
        self.meter.as_deref()
    }

    /// The factor of every camera ray's contribution: pi for an irradiance meter (its rays'
    /// cosine-weighted directions), one otherwise.
    #[inline]
    pub fn ray_weight(&self) -> f32 {
        match self.meter() {
            Some(Meter::Irradiance { .. }) => std::f32::consts::PI,
            _ => 1.0,
        }
    }

    /// A meter's ray: the film point's place in its pixel chooses the point of the surface,
    /// `u_dir` the direction.
    fn meter_ray(&self, meter: &Meter, film: Vec2, u_dir: Vec2) -> Ray {
        match meter {
            Meter::Radiance => Ray::new(self.position, self.forward),
            Meter::Irradiance { shapes, by_area } => {
                let u = film - film.floor();
                let (x, _, i) = by_area.sample_continuous(u.x);
                let ux = (x * shapes.len() as f32 - i as f32)
                    .clamp(0.0, crate::sampling::ONE_MINUS_EPSILON);
                let (p, n) = shapes[i].sample_area(Vec2::new(ux, u.y));
                let dir = to_world(cosine_hemisphere(u_dir), n);
                Ray::new(offset_origin(p, n, dir), dir)
            }
        }
    }

    /// An orthographic camera at `position` looking towards `look_at`: its view is
    /// `view_height` world units tall (and as wide as the image's aspect makes it), centred
    /// on the optical axis unless shifted ([`Camera::with_shift`], in world units).
    pub fn orthographic(
        position: Vec3,
        look_at: Vec3,
        up: Vec3,
        view_height: f32,
        width: u32,
        height: u32,
    ) -> Camera {
        let mut camera = Camera::new(position, look_at, up, 90.0, width, height);
        camera.tan_half = 0.5 * view_height;
        camera.orthographic = true;
        camera
    }

    /// Whether the camera's rays are parallel (its importance a delta in direction).
    #[inline]
    pub fn is_orthographic(&self) -> bool {
        self.orthographic
    }

    /// The width of a pixel on the view of an orthographic camera (world units); None for a
    /// perspective camera, whose pixels' footprints grow with distance.
    pub fn orthographic_pixel(&self) -> Option<f32> {
        self.orthographic
            .then(|| 2.0 * self.tan_half / self.height as f32)
    }

    /// The camera with a thin lens of radius `lens_radius` focused at `focal_distance` (both
    /// positive; a zero radius keeps the pinhole).
    pub fn with_lens(mut self, lens_radius: f32, focal_distance: f32) -> Camera {
        if lens_radius > 0.0 && !self.orthographic {
            self.lens_radius = lens_radius;
            self.focal_distance = focal_distance;
        }
        self
    }

    /// The lens's radius (zero for a pinhole) and the distance it focuses at.
    pub fn lens(&self) -> (f32, f32) {
        (self.lens_radius, self.focal_distance)
    }

    /// Area of the lens: one for a pinhole (a delta in position, pbrt-v4's convention).
    #[inline]
    fn lens_area(&self) -> f32 {
        if self.lens_radius > 0.0 {
            std::f32::consts::PI * self.lens_radius * self.lens_radius
        } else {
            1.0
        }
    }

    /// The point of the lens for a uniform sample `u` of the unit square.
    #[inline]
    fn lens_point(&self, u: Vec2) -> Vec3 {
        let d = crate::sampling::concentric_disc(u) * self.lens_radius;
        self.position + d.x * self.right + d.y * self.up
    }

    /// The camera with its image mirrored left to right (a camera transform whose
    /// determinant is negative: Mitsuba's `<scale x="-1"/>`, pbrt's `Scale -1 1 1`).
    pub fn mirrored(mut self) -> Camera {
        self.right = -self.right;
        self
    }

    /// The camera with its image's centre moved to `shift` on the plane at distance 1 (in
    /// units of that plane, along the image's x to the right and y up): a window off the
    /// optical axis, as a crop of a larger image is, or pbrt's `screenwindow`. The field of
    /// view stays the image's height.
    pub fn with_shift(mut self, shift: Vec2) -> Camera {
        self.shift = shift;
        self
    }

    pub fn resolution(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The ray from the pinhole (the lens's centre) through a point on the film in pixel
    /// units: (0, 0) is the top-left corner.
    pub fn generate_ray(&self, film: Vec2) -> Ray {
        if let Some(meter) = self.meter() {
            return self.meter_ray(meter, film, Vec2::splat(0.5));
        }
        if self.orthographic {
            let (sx, sy) = self.screen(film);
            return Ray::new(self.position + sx * self.right + sy * self.up, self.forward);
        }
        Ray::new(self.position, self.towards(film).normalize())
    }

    /// The camera ray through a point on the film: from the lens point that `lens` (a uniform
    /// sample of the unit square, drawn only if the camera has a lens) gives, through the
    /// point of the plane of focus [`Camera::generate_ray`]'s ray reaches.
    ///
    /// A meter's ray: an irradiance meter's direction from `lens` (always drawn), its point on
    /// the surface from where the film point lies in the pixel (uniform for a box filter).
    pub fn generate_ray_lens(&self, film: Vec2, lens: impl FnOnce() -> Vec2) -> Ray {
        if let Some(meter) = self.meter() {
            return self.meter_ray(meter, film, lens());
        }
        if self.lens_radius <= 0.0 {
            return self.generate_ray(film);
        }
        let focus = self.position + self.focal_distance * self.towards(film);
        let origin = self.lens_point(lens());
        Ray::new(origin, (focus - origin).normalize())
    }

    /// The direction from the pinhole through a film point, its component along the optical
    /// axis one.
    #[inline]
    fn towards(&self, film: Vec2) -> Vec3 {
        let (sx, sy) = self.screen(film);
        self.forward + sx * self.right + sy * self.up
    }

    /// A film point's place on the image plane at distance 1 (orthographic: on the view),
    /// along `right` and `up` from the optical axis.
    #[inline]
    fn screen(&self, film: Vec2) -> (f32, f32) {
        let aspect = self.width as f32 / self.height as f32;
        // The shift is +0 for a centred window, and x + 0 is x (never -0 here): a centred
        // camera's rays are those of the plain formula, bit for bit.
        let sx = (2.0 * film.x / self.width as f32 - 1.0) * self.tan_half * aspect + self.shift.x;
        let sy = (1.0 - 2.0 * film.y / self.height as f32) * self.tan_half + self.shift.y;
        (sx, sy)
    }

    /// Area of the image on the plane at distance 1 in front of the pinhole (orthographic:
    /// of the view, in world units).
    #[inline]
    pub fn image_area(&self) -> f32 {
        let aspect = self.width as f32 / self.height as f32;
        4.0 * self.tan_half * self.tan_half * aspect
    }

    /// The optical axis (unit, from the pinhole into the scene).
    #[inline]
    pub fn forward(&self) -> Vec3 {
        self.forward
    }

    /// The importance We of a camera ray (from the pinhole, or from a point of the lens) and
    /// the film point it goes through; None outside the image widened by `margin` pixels on
    /// every side (see the module comment: the reach of the reconstruction filter,
    /// [`FilterSampler::margin`]).
    ///
    /// [`FilterSampler::margin`]: crate::filter::FilterSampler::margin
    #[inline]
    pub fn we(&self, ray: &Ray, margin: f32) -> Option<(f32, Vec2)> {
        let cos = ray.dir.dot(self.forward);
        if cos <= 0.0 || self.orthographic || self.meter.is_some() {
            return None;
        }
        let film = self.film_of(ray, cos, margin)?;
        let cos2 = cos * cos;
        Some((
            1.0 / (self.image_area() * self.lens_area() * cos2 * cos2),
            film,
        ))
    }

    /// Where a camera ray crosses the film, widened by `margin` pixels: the pinhole's
    /// projection of the point where it crosses the plane of focus (`cos`, its direction's
    /// component along the optical axis, positive).
    #[inline]
    fn film_of(&self, ray: &Ray, cos: f32, margin: f32) -> Option<Vec2> {
        if self.lens_radius <= 0.0 {
            return self.project_within(self.position + ray.dir, margin);
        }
        let focus = ray.origin + (self.focal_distance / cos) * ray.dir;
        self.project_within(focus, margin)
    }

    /// The densities with which camera rays leave the camera along `ray`: in position 1 / the
    /// lens's area (1 for the pinhole, a delta), in direction 1 / (A cos^3 theta) (A the
    /// image's area at distance 1), zero outside the image widened by `margin` pixels.
    /// pbrt-v4's `PDF_We`.
    #[inline]
    pub fn pdf_we(&self, ray: &Ray, margin: f32) -> (f32, f32) {
        let cos = ray.dir.dot(self.forward);
        let pos = 1.0 / self.lens_area();
        if cos <= 0.0 || self.film_of(ray, cos, margin).is_none() {
            return (pos, 0.0);
        }
        (pos, 1.0 / (self.image_area() * cos * cos * cos))
    }

    /// The density with which the camera samples `ray`, in the measure its first segment
    /// converts from: per solid angle for a perspective camera (`pdf_we`'s direction density),
    /// per unit area of the view for an orthographic one (1 / its area: its direction is a
    /// delta); zero outside the image widened by `margin` pixels. Per whole image, as
    /// `pdf_we`.
    #[inline]
    pub fn pdf_ray(&self, ray: &Ray, margin: f32) -> f32 {
        if self.orthographic {
            let d = ray.origin - self.position;
            let inside = self
                .view_to_film(d.dot(self.right), d.dot(self.up), margin)
                .is_some();
            return if inside { 1.0 / self.image_area() } else { 0.0 };
        }
        self.pdf_we(ray, margin).1
    }

    /// The density per unit area (per unit volume in a medium, `cos` 1) at the point `dist`
    /// along `ray` of the camera having sampled it: `pdf_ray` times `cos` (the cosine there)
    /// over dist^2 for a perspective camera, with no distance for an orthographic one.
    #[inline]
    pub fn pdf_area(&self, ray: &Ray, margin: f32, cos: f32, dist: f32) -> f32 {
        if self.orthographic {
            return self.pdf_ray(ray, margin) * cos;
        }
        self.pdf_we(ray, margin).1 * cos / (dist * dist)
    }

    /// The connection from the point `p` to the camera (pbrt-v4's `SampleWi`): a point of the
    /// lens (from `lens`, a uniform sample of the unit square drawn only if the camera has a
    /// lens), the direction towards it, the importance of the ray from there through `p`, its
    /// density at `p`, and where on the film `p` lands; None if `p` is behind the camera or
    /// lands outside the image widened by `margin` pixels.
    pub fn sample_wi(
        &self,
        p: Vec3,
        margin: f32,
        lens: impl FnOnce() -> Vec2,
    ) -> Option<CameraSample> {
        if self.meter.is_some() {
            return None;
        }
        if self.orthographic {
            // Seen along -forward only, from the point of the view p projects to.
            let d = p - self.position;
            let z = d.dot(self.forward);
            let (x, y) = (d.dot(self.right), d.dot(self.up));
            if z <= 0.0 {
                return None;
            }
            let film = self.view_to_film(x, y, margin)?;
            return Some(CameraSample {
                p: self.position + x * self.right + y * self.up,
                wi: -self.forward,
                dist: z,
                we: 1.0 / self.image_area(),
                pdf: 1.0,
                film,
                cos: 1.0,
            });
        }
        let at = if self.lens_radius > 0.0 {
            self.lens_point(lens())
        } else {
            self.position
        };
        let d = at - p;
        let dist2 = d.length_squared();
        if dist2 == 0.0 {
            return None;
        }
        let dist = dist2.sqrt();
        let wi = d / dist;
        let (we, film) = self.we(&Ray::new(at, -wi), margin)?;
        let cos = (-wi).dot(self.forward);
        Some(CameraSample {
            p: at,
            wi,
            dist,
            we,
            pdf: dist2 / (cos * self.lens_area()),
            film,
            cos,
        })
    }

    /// The pixel (continuous film coordinates) a world point projects to, if it is in front
    /// of the camera and inside the image.
    pub fn project(&self, p: Vec3) -> Option<Vec2> {
        self.project_within(p, 0.0)
    }

    /// [`Camera::project`] into the image widened by `margin` pixels on every side.
    pub fn project_within(&self, p: Vec3, margin: f32) -> Option<Vec2> {
        if self.meter.is_some() {
            return None;
        }
        let d = p - self.position;
        let z = d.dot(self.forward);
        if z <= 0.0 {
            return None;
        }
        if self.orthographic {
            return self.view_to_film(d.dot(self.right), d.dot(self.up), margin);
        }
        self.view_to_film(d.dot(self.right) / z, d.dot(self.up) / z, margin)
    }

    /// The film point of a point of the image plane at distance 1 (orthographic: of the
    /// view), at `x` along `right` and `y` along `up` from the optical axis; None outside
    /// the image widened by `margin` pixels.
    #[inline]
    fn view_to_film(&self, x: f32, y: f32, margin: f32) -> Option<Vec2> {
        let aspect = self.width as f32 / self.height as f32;
        let sx = (x - self.shift.x) / (self.tan_half * aspect);
        let sy = (y - self.shift.y) / self.tan_half;
        let film = Vec2::new(
            (sx + 1.0) * 0.5 * self.width as f32,
            (1.0 - sy) * 0.5 * self.height as f32,
        );
        (film.x >= -margin
            && film.y >= -margin
            && film.x < self.width as f32 + margin
            && film.y < self.height as f32 + margin)
            .then_some(film)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 64 x 48 camera looking down and to the side, its up vector not orthogonal to its
    /// view direction.
    fn oblique_camera() -> Camera {
        Camera::new(
            Vec3::new(0.3, 1.2, 3.0),
            Vec3::new(-0.2, 0.8, 0.0),
            Vec3::Y,
            50.0,
            64,
            48,
        )
    }

    #[test]
    fn right_is_right_and_up_is_up() {
        let cam = Camera::new(
            Vec3::new(0.0, 1.0, 3.9),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::Y,
            39.3,
            256,
            128,
        );
        let center = cam.generate_ray(Vec2::new(128.0, 64.0));
        assert!((center.dir - Vec3::NEG_Z).length() < 1e-6);
        let right = cam.generate_ray(Vec2::new(256.0, 64.0));
        assert!(right.dir.x > 0.0);
        let top = cam.generate_ray(Vec2::new(128.0, 0.0));
        assert!(top.dir.y > 0.0);
        let p = right.at(2.0);
        let back = cam.project(Vec3::new(0.5, 1.2, 0.0)).unwrap();
        let ray = cam.generate_ray(back);
        let expect = (Vec3::new(0.5, 1.2, 0.0) - cam.position).normalize();
        assert!((ray.dir - expect).length() < 1e-4, "{p}");
    }

    /// The oblique camera, and the same mirrored with its window off the axis.
    fn cameras() -> [Camera; 2] {
        [
            oblique_camera(),
            oblique_camera().mirrored().with_shift(Vec2::new(0.3, -0.2)),
        ]
    }

    #[test]
    fn a_point_on_a_camera_ray_projects_to_its_pixel() {
        for cam in cameras() {
            projects_to_its_pixel(cam);
        }
    }

    fn projects_to_its_pixel(cam: Camera) {
        for film in [
            Vec2::new(0.5, 0.5),
            Vec2::new(13.25, 40.75),
            Vec2::new(32.0, 24.0),
            Vec2::new(63.5, 47.5),
        ] {
            for t in [0.1, 1.0, 7.5] {
                let p = cam.generate_ray(film).at(t);
                let back = cam.project(p).expect("in front and inside the image");
                assert!((back - film).length() < 1e-3, "{film} -> {back}");
            }
        }
        // Behind the camera and outside the field of view: no pixel.
        assert_eq!(cam.project(cam.position - cam.forward), None);
        let outside = cam.generate_ray(Vec2::new(-10.0, 24.0)).at(2.0);
        assert_eq!(cam.project(outside), None);
    }

    /// The importance integrates to one over the image's directions (so that We cos / pdf_dir
    /// = 1 for a camera ray), its density matches the uniform film position the pixel loop
    /// draws, and `sample_wi` lands where `generate_ray` started.
    #[test]
    fn importance_is_normalised_and_consistent_with_camera_rays() {
        for cam in cameras() {
            importance_is_normalised(cam);
        }
    }

    fn importance_is_normalised(cam: Camera) {
        // Monte Carlo over the sphere of directions: the integral of pdf_dir is 1, and so is
        // the integral of We cos (the importance of the whole image).
        let mut rng = crate::sampling::Rng::new(&[7]);
        let n = 400_000;
        let (mut pdf_sum, mut we_sum) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let w = crate::sampling::uniform_sphere(rng.next_2d());
            let (_, pdf) = cam.pdf_we(&Ray::new(cam.position, w), 0.0);
            pdf_sum += pdf as f64;
            if let Some((we, _)) = cam.we(&Ray::new(cam.position, w), 0.0) {
                we_sum += (we * w.dot(cam.forward)) as f64;
            }
        }
        let scale = 4.0 * std::f64::consts::PI / n as f64;
        assert!((pdf_sum * scale - 1.0).abs() < 0.02, "{}", pdf_sum * scale);
        assert!((we_sum * scale - 1.0).abs() < 0.02, "{}", we_sum * scale);
        // A camera ray through a film point: the density of its direction when film points are
        // uniform over the image is (1 / (W H)) |d film / d w| = 1 / (A cos^3).
        for film in [
            Vec2::new(3.5, 40.25),
            Vec2::new(32.0, 24.0),
            Vec2::new(60.0, 2.0),
        ] {
            let ray = cam.generate_ray(film);
            let p = ray.at(2.5);
            let s = cam.sample_wi(p, 0.0, || Vec2::ZERO).unwrap();
            assert!((s.film - film).length() < 1e-3);
            assert!((s.wi + ray.dir).length() < 1e-5);
            assert!((s.dist - 2.5).abs() < 1e-4);
            let (_, pdf_dir) = cam.pdf_we(&ray, 0.0);
            assert!((s.we * s.cos / pdf_dir - 1.0).abs() < 1e-5);
            // Finite differences of the film position with the direction: the Jacobian.
            let h = 1e-3;
            let a = cam.generate_ray(film + Vec2::new(h, 0.0)).dir;
            let b = cam.generate_ray(film + Vec2::new(0.0, h)).dir;
            let solid = (a - ray.dir).cross(b - ray.dir).length() / (h * h);
            let want = 1.0 / (64.0 * 48.0) / solid;
            assert!((pdf_dir / want - 1.0).abs() < 0.01, "{pdf_dir} vs {want}");
        }
        assert!(
            cam.sample_wi(cam.position - cam.forward, 0.0, || Vec2::ZERO)
                .is_none()
        );
        // Just outside the image: only within a margin.
        let outside = cam.generate_ray(Vec2::new(-0.7, 10.0)).at(2.0);
        assert!(cam.sample_wi(outside, 0.0, || Vec2::ZERO).is_none());
        let s = cam.sample_wi(outside, 1.0, || Vec2::ZERO).unwrap();
        assert!((s.film - Vec2::new(-0.7, 10.0)).length() < 1e-3);
    }

    /// A crop of an image is the camera of the crop's size, its field of view the crop's
    /// height, shifted to the crop's centre: each of its rays is the full camera's through the
    /// same point. Mirrored, a film point's ray is the plain camera's through the point
    /// mirrored about the image's middle column.
    #[test]
    fn crops_are_shifted_cameras_and_mirrors_mirror() {
        let (w, h) = (64.0f32, 48.0f32);
        let full = oblique_camera();
        let (x0, y0, cw, ch) = (40.0f32, 6.0f32, 20.0f32, 10.0f32);
        let tan_v = full.tan_half;
        let tan_crop = tan_v * ch / h;
        let shift = Vec2::new(
            ((2.0 * x0 + cw) / w - 1.0) * tan_v * (w / h),
            (1.0 - (2.0 * y0 + ch) / h) * tan_v,
        );
        let crop = Camera::new(
            full.position,
            full.position + full.forward,
            full.up,
            2.0 * tan_crop.atan().to_degrees(),
            cw as u32,
            ch as u32,
        )
        .with_shift(shift);
        for film in [
            Vec2::new(0.0, 0.0),
            Vec2::new(7.25, 3.5),
            Vec2::new(20.0, 10.0),
        ] {
            let a = crop.generate_ray(film).dir;
            let b = full.generate_ray(film + Vec2::new(x0, y0)).dir;
            assert!((a - b).length() < 1e-5, "{film}: {a} vs {b}");
        }
        let mirror = oblique_camera().mirrored();
        for film in [Vec2::new(3.0, 5.0), Vec2::new(50.5, 40.0)] {
            let a = mirror.generate_ray(film).dir;
            let b = full.generate_ray(Vec2::new(w - film.x, film.y)).dir;
            assert!((a - b).length() < 1e-6, "{film}: {a} vs {b}");
        }
        // A centred camera's rays are those without a shift, bit for bit.
        let centred = oblique_camera().with_shift(Vec2::ZERO);
        let f = Vec2::new(11.3, 29.9);
        assert_eq!(centred.generate_ray(f).dir, full.generate_ray(f).dir);
    }

    /// The oblique camera with a lens of radius 0.2 focused at 3.
    fn lens_camera() -> Camera {
        oblique_camera().with_lens(0.2, 3.0)
    }

    /// A thin lens: every ray through a film point meets the pinhole's ray through it on the
    /// plane of focus, and a point there lands on that film point from every lens point; the
    /// importance integrates to one over the lens and the directions; and `sample_wi` is
    /// consistent with `pdf_we` (We cos / pdf_dir = 1 / lens area).
    #[test]
    fn a_thin_lens_focuses_and_its_importance_is_normalised() {
        for cam in [
            lens_camera(),
            lens_camera().mirrored().with_shift(Vec2::new(0.1, 0.2)),
        ] {
            let mut rng = crate::sampling::Rng::new(&[11]);
            let lens_area = std::f32::consts::PI * 0.2 * 0.2;
            for film in [
                Vec2::new(3.5, 40.25),
                Vec2::new(32.0, 24.0),
                Vec2::new(60.0, 2.0),
            ] {
                let pinhole = cam.generate_ray(film);
                let focus = pinhole.at(3.0 / pinhole.dir.dot(cam.forward));
                for _ in 0..8 {
                    let ray = cam.generate_ray_lens(film, || rng.next_2d());
                    assert!((ray.origin - cam.position).length() <= 0.2 + 1e-6);
                    assert!((ray.origin - cam.position).dot(cam.forward).abs() < 1e-6);
                    let t = (focus - ray.origin).dot(ray.dir);
                    assert!((ray.at(t) - focus).length() < 1e-4, "{film}");
                    let (we, back) = cam.we(&ray, 0.0).expect("inside the image");
                    assert!((back - film).length() < 1e-2, "{film} -> {back}");
                    let (pos, dir) = cam.pdf_we(&ray, 0.0);
                    assert!((pos * lens_area - 1.0).abs() < 1e-5);
                    assert!((we * ray.dir.dot(cam.forward) / dir * lens_area - 1.0).abs() < 1e-4);
                    let s = cam.sample_wi(focus, 0.0, || rng.next_2d()).unwrap();
                    assert!((s.film - film).length() < 1e-2, "{film} -> {}", s.film);
                    let cos = s.cos;
                    let want = s.dist * s.dist / (cos * lens_area);
                    assert!((s.pdf / want - 1.0).abs() < 1e-5);
                }
                // Off the plane of focus, the lens points spread a point over the film.
                let near = pinhole.at(1.0);
                let a = cam.sample_wi(near, 100.0, || Vec2::new(0.0, 0.5)).unwrap();
                let b = cam.sample_wi(near, 100.0, || Vec2::new(1.0, 0.5)).unwrap();
                assert!((a.film - b.film).length() > 1.0, "{} {}", a.film, b.film);
            }
            // Monte Carlo over the lens and the sphere of directions: the integral of We cos
            // is one, and so is each lens point's integral of pdf_dir.
            let n = 400_000;
            let (mut pdf_sum, mut we_sum) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let origin = cam.lens_point(rng.next_2d());
                let w = crate::sampling::uniform_sphere(rng.next_2d());
                let ray = Ray::new(origin, w);
                pdf_sum += cam.pdf_we(&ray, 0.0).1 as f64;
                if let Some((we, _)) = cam.we(&ray, 0.0) {
                    we_sum += (we * w.dot(cam.forward)) as f64;
                }
            }
            let scale = 4.0 * std::f64::consts::PI / n as f64;
            assert!((pdf_sum * scale - 1.0).abs() < 0.02, "{}", pdf_sum * scale);
            let we_total = we_sum * scale * lens_area as f64;
            assert!((we_total - 1.0).abs() < 0.02, "{we_total}");
        }
        // A zero radius is the pinhole, bit for bit.
        let pin = oblique_camera().with_lens(0.0, 3.0);
        let f = Vec2::new(10.2, 33.3);
        let ray = pin.generate_ray_lens(f, || unreachable!("a pinhole draws no lens sample"));
        assert_eq!(ray.dir, oblique_camera().generate_ray(f).dir);
    }

    /// An orthographic camera: its rays are parallel to the axis from the view's points, a
    /// point lands where its ray started, `sample_wi` projects along the axis with the
    /// importance 1 / A of a delta direction, and the density of a ray is 1 / A on the view.
    #[test]
    fn orthographic_rays_are_parallel_and_project_back() {
        for cam in [
            Camera::orthographic(Vec3::new(0.3, 1.2, 3.0), Vec3::ZERO, Vec3::Y, 2.5, 64, 48),
            Camera::orthographic(Vec3::new(0.3, 1.2, 3.0), Vec3::ZERO, Vec3::Y, 2.5, 64, 48)
                .mirrored()
                .with_shift(Vec2::new(0.4, -0.1)),
        ] {
            let area = 2.5 * 2.5 * 64.0 / 48.0;
            assert!((cam.image_area() - area).abs() < 1e-5);
            assert_eq!(cam.orthographic_pixel(), Some(2.5 / 48.0));
            for film in [
                Vec2::new(0.5, 0.5),
                Vec2::new(13.25, 40.75),
                Vec2::new(63.5, 47.5),
            ] {
                let ray = cam.generate_ray(film);
                assert!((ray.dir - cam.forward).length() < 1e-6);
                assert!((ray.origin - cam.position).dot(cam.forward).abs() < 1e-5);
                assert!((cam.pdf_ray(&ray, 0.0) * area - 1.0).abs() < 1e-5);
                for t in [0.1, 5.0] {
                    let p = ray.at(t);
                    let back = cam.project(p).expect("in front and inside the view");
                    assert!((back - film).length() < 1e-3, "{film} -> {back}");
                    let s = cam.sample_wi(p, 0.0, || unreachable!()).unwrap();
                    assert!((s.film - film).length() < 1e-3);
                    assert!((s.p - ray.origin).length() < 1e-4);
                    assert!((s.dist - t).abs() < 1e-4 && s.wi == -cam.forward);
                    assert!((s.we / s.pdf * area - 1.0).abs() < 1e-5);
                    let cos = 0.5;
                    let pdf = cam.pdf_area(&Ray::new(s.p, -s.wi), 0.0, cos, s.dist);
                    assert!((pdf * area - cos).abs() < 1e-5, "no distance fall-off");
                }
            }
            // Behind the view's plane and outside the view: not seen.
            assert!(
                cam.sample_wi(cam.position - cam.forward, 0.0, || Vec2::ZERO)
                    .is_none()
            );
            let outside = cam.generate_ray(Vec2::new(-3.0, 10.0));
            assert_eq!(cam.pdf_ray(&outside, 0.0), 0.0);
            assert!(cam.sample_wi(outside.at(1.0), 0.0, || Vec2::ZERO).is_none());
            // A lens is not an orthographic camera's.
            assert_eq!(cam.clone().with_lens(0.5, 2.0).lens().0, 0.0);
        }
    }
}
