//! A pinhole camera with a vertical field of view.

use crate::geometry::Ray;
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct Camera {
    pub position: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    /// tan(fov/2): half the height of the image plane at distance 1.
    tan_half: f32,
    width: u32,
    height: u32,
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
            width,
            height,
        }
    }

    pub fn resolution(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The ray through a point on the film in pixel units: (0, 0) is the top-left corner.
    pub fn generate_ray(&self, film: Vec2) -> Ray {
        let aspect = self.width as f32 / self.height as f32;
        let sx = (2.0 * film.x / self.width as f32 - 1.0) * self.tan_half * aspect;
        let sy = (1.0 - 2.0 * film.y / self.height as f32) * self.tan_half;
        Ray::new(
            self.position,
            (self.forward + sx * self.right + sy * self.up).normalize(),
        )
    }

    /// The pixel (continuous film coordinates) a world point projects to, if it is in front
    /// of the camera and inside the image.
    pub fn project(&self, p: Vec3) -> Option<Vec2> {
        let d = p - self.position;
        let z = d.dot(self.forward);
        if z <= 0.0 {
            return None;
        }
        let aspect = self.width as f32 / self.height as f32;
        let sx = d.dot(self.right) / z / (self.tan_half * aspect);
        let sy = d.dot(self.up) / z / self.tan_half;
        let film = Vec2::new(
            (sx + 1.0) * 0.5 * self.width as f32,
            (1.0 - sy) * 0.5 * self.height as f32,
        );
        (film.x >= 0.0
            && film.y >= 0.0
            && film.x < self.width as f32
            && film.y < self.height as f32)
            .then_some(film)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn a_point_on_a_camera_ray_projects_to_its_pixel() {
        let cam = Camera::new(
            Vec3::new(0.3, 1.2, 3.0),
            Vec3::new(-0.2, 0.8, 0.0),
            Vec3::Y,
            50.0,
            64,
            48,
        );
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
}
