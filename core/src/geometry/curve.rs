//! Pieces of round curves: the convex hull of two spheres, (p0, r0) and (p1, r1). It is a
//! truncated cone touching both spheres along two circles (its "body"), closed at either end
//! by the part of that end's sphere beyond the circle (a cap), or left open there. A chain of
//! pieces sharing their end spheres is Embree's round linear curve, which Mitsuba 3's
//! `linearcurve` renders; a fine chain of them follows the swept circle of its `bsplinecurve`.
//!
//! In the plane through the axis, with y along the axis from p0 and rho the distance from it,
//! the cone's side is the line y sin(phi) + rho cos(phi) = r0, where sin(phi) = (r0 - r1) / L
//! and L = |p1 - p0|. Its outward normal is (sin(phi), cos(phi)), and along it runs the
//! coordinate y cos(phi) - rho sin(phi): 0 on the circle where it touches the first sphere,
//! L cos(phi) on the second. Points with a smaller coordinate lie on the first cap, with a
//! larger one on the second.
//!
//! Rays meet a piece only where they enter it: a ray starting inside passes out unseen, as
//! through Embree's curves with back-face culling (Mitsuba 3's build). The sphere that joins a
//! piece to the next one stops at the plane where the next piece begins, as Embree's does.

use super::{Ray, sphere_roots};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Which spheres close the piece: [`START_CAP`] at p0, [`END_CAP`] at p1.
pub const START_CAP: u8 = 1;
pub const END_CAP: u8 = 2;

#[derive(Clone, Copy, Debug)]
pub(super) struct Piece {
    pub p0: Vec3,
    pub r0: f32,
    pub p1: Vec3,
    pub r1: f32,
    /// The unit axis of the next piece of the curve, or zero.
    pub next: Vec3,
    pub caps: u8,
}

/// The cone's terms; None where one sphere holds the other (the piece is the larger one).
#[derive(Clone, Copy)]
struct Cone {
    axis: Vec3,
    len: f32,
    sin: f32,
    cos: f32,
}

/// Where on the piece a point lies.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Part {
    Start,
    Body,
    End,
}

impl Piece {
    #[inline]
    fn cone(&self) -> Option<Cone> {
        let w = self.p1 - self.p0;
        let len = w.length();
        let sin = (self.r0 - self.r1) / len;
        // Also NaN (p0 = p1): no cone.
        if sin.is_nan() || sin.abs() >= 1.0 {
            return None;
        }
        Some(Cone {
            axis: w / len,
            len,
            sin,
            cos: (1.0 - sin * sin).sqrt(),
        })
    }

    /// The sphere a piece without a cone is.
    #[inline]
    fn larger(&self) -> (Vec3, f32) {
        if self.r0 >= self.r1 {
            (self.p0, self.r0)
        } else {
            (self.p1, self.r1)
        }
    }

    /// The part a point on (or near) the surface lies on.
    #[inline]
    fn part(&self, cone: &Cone, p: Vec3) -> Part {
        let x = p - self.p0;
        let y = x.dot(cone.axis);
        let rho = (x - y * cone.axis).length();
        let coordinate = y * cone.cos - rho * cone.sin;
        if coordinate <= 0.0 {
            Part::Start
        } else if coordinate >= cone.len * cone.cos {
            Part::End
        } else {
            Part::Body
        }
    }

    /// Distance along the ray to where it enters the piece, within (0, tmax).
    #[inline]
    pub fn intersect(&self, ray: &Ray, tmax: f32) -> Option<f32> {
        let within = |t: f32| (t > 0.0 && t < tmax).then_some(t);
        let Some(cone) = self.cone() else {
            let (c, r) = self.larger();
            let (t0, t1) = sphere_roots(ray, c, r)?;
            return within(t0.min(t1));
        };
        let Cone {
            axis,
            len,
            sin,
            cos,
        } = cone;
        // The cone's side: cos^2 (|x|^2 - y^2) = (r0 - y sin)^2 along x = oa + t d, a
        // quadratic a t^2 + 2 b t + c. Where it is negative the ray is inside the (double)
        // cone: the smaller-or-larger root with -sqrt is where it goes in, whatever the sign of a.
        let oa = ray.origin - self.p0;
        let (y0, dy) = (oa.dot(axis), ray.dir.dot(axis));
        let cos2 = cos * cos;
        let a = cos2 - dy * dy;
        let b = cos2 * (oa.dot(ray.dir) - y0 * dy) + sin * dy * (self.r0 - sin * y0);
        let c = cos2 * (oa.dot(oa) - y0 * y0) - (self.r0 - sin * y0).powi(2);
        let h = b * b - a * c;
        // Both spheres lie inside the cone: a ray that misses it misses the piece.
        if h < 0.0 {
            return None;
        }
        if a != 0.0 {
            let t = (-b - h.sqrt()) / a;
            let x = oa + t * ray.dir;
            let y = x.dot(axis);
            let rho = (x - y * axis).length();
            let coordinate = y * cos - rho * sin;
            // On the nappe the spheres are in, between the two circles: the body, where the
            // ray enters the piece (a convex body is entered once).
            if self.r0 - sin * y >= 0.0 && coordinate >= 0.0 && coordinate <= len * cos {
                return within(t);
            }
        }
        // Else it enters through a cap, if at all: the nearer of the caps' entries, each
        // on its own part of its sphere (not a sphere's inner part, seen through an open end).
        let slack = 1e-3 * (len + self.r0.max(self.r1));
        let mut best = None;
        for (centre, r, cap, part) in [
            (self.p0, self.r0, START_CAP, Part::Start),
            (self.p1, self.r1, END_CAP, Part::End),
        ] {
            if self.caps & cap == 0 {
                continue;
            }
            let Some((t0, t1)) = sphere_roots(ray, centre, r) else {
                continue;
            };
            let t = t0.min(t1);
            if t <= 0.0 {
                if t0.max(t1) > 0.0 {
                    // The ray starts inside the piece.
                    return None;
                }
                continue;
            }
            let x = oa + t * ray.dir;
            let y = x.dot(axis);
            let coordinate = y * cos - (x - y * axis).length() * sin;
            // A joint's sphere ends where the next piece begins (Embree drops the hits
            // beyond the next cone's plane): its part there lies inside that piece, and is
            // seen only from inside the tube, through an open end.
            let on_cap = match part {
                Part::Start => coordinate <= slack,
                _ => {
                    coordinate >= len * cos - slack
                        && (oa + t * ray.dir - (self.p1 - self.p0)).dot(self.next) <= slack
                }
            };
            if on_cap && best.is_none_or(|b| t < b) {
                best = Some(t);
            }
        }
        best.and_then(within)
    }

    /// The outward unit normal at a point on the surface.
    #[inline]
    pub fn normal(&self, p: Vec3) -> Vec3 {
        let Some(cone) = self.cone() else {
            return (p - self.larger().0).normalize();
        };
        match self.part(&cone, p) {
            Part::Start => (p - self.p0).normalize(),
            Part::End => (p - self.p1).normalize(),
            Part::Body => {
                let x = p - self.p0;
                let radial = (x - x.dot(cone.axis) * cone.axis).normalize();
                cone.sin * cone.axis + cone.cos * radial
            }
        }
    }

    /// Mitsuba 3's parameterisation of a curve at `p` (a point on the piece with outward
    /// normal `n`): u the angle about the axis / 2 pi, from the axis' frame towards +z, and
    /// v = v0 + (v1 - v0) s with s where along the axis the sphere through p is centred;
    /// with dp/du and dp/dv.
    pub fn surface(&self, p: Vec3, n: Vec3, v0: f32, v1: f32) -> (Vec2, Vec3, Vec3) {
        let w = self.p1 - self.p0;
        let len = w.length();
        let axis = if len > 0.0 { w / len } else { Vec3::Z };
        // The centre of the sphere the point lies on: along -n from p, on the axis.
        let s = match self.cone() {
            None => {
                if self.r0 >= self.r1 {
                    0.0
                } else {
                    1.0
                }
            }
            Some(cone) => match self.part(&cone, p) {
                Part::Start => 0.0,
                Part::End => 1.0,
                Part::Body => {
                    let x = p - self.p0;
                    let rho = (x - x.dot(axis) * axis).length();
                    let centre = p - (rho / cone.cos) * n;
                    ((centre - self.p0).dot(axis) / len).clamp(0.0, 1.0)
                }
            },
        };
        let centre = self.p0 + s * w;
        let r = self.r0 + s * (self.r1 - self.r0);
        let radial = (p - centre).normalize_or(n);
        // Mitsuba's frame about the axis: z made orthogonal to it (y for an axis along z).
        let up = if axis.z.abs() == 1.0 {
            Vec3::Y
        } else {
            Vec3::Z
        };
        let u_rot = (up - axis * axis.dot(up)).normalize();
        let u_rad = u_rot.cross(axis);
        let mut u = radial.dot(u_rot).atan2(radial.dot(u_rad)) * (0.5 / PI);
        if u < 0.0 {
            u += 1.0;
        }
        let v = v0 + s * (v1 - v0);
        let dpdu = 2.0 * PI * r * axis.cross(radial);
        let dpdv = (w + (self.r1 - self.r0) * radial) / (v1 - v0);
        (Vec2::new(u, v), dpdu, dpdv)
    }

    /// The areas of the start cap, the body and the end cap.
    #[inline]
    fn areas(&self, cone: &Cone) -> [f32; 3] {
        let cap = |on: bool, r: f32, height: f32| if on { 2.0 * PI * r * r * height } else { 0.0 };
        [
            cap(self.caps & START_CAP != 0, self.r0, 1.0 + cone.sin),
            PI * cone.cos * cone.cos * (self.r0 + self.r1) * cone.len,
            cap(self.caps & END_CAP != 0, self.r1, 1.0 - cone.sin),
        ]
    }

    pub fn area(&self) -> f32 {
        match self.cone() {
            None => 4.0 * PI * self.larger().1.powi(2),
            Some(cone) => self.areas(&cone).iter().sum(),
        }
    }

    /// A point distributed uniformly by area, and the normal there.
    pub fn sample_area(&self, u: Vec2) -> (Vec3, Vec3) {
        let Some(cone) = self.cone() else {
            let (c, r) = self.larger();
            let d = crate::sampling::uniform_sphere(u);
            return (c + r * d, d);
        };
        let [start, body, end] = self.areas(&cone);
        let total = start + body + end;
        let frame = crate::bsdf::Frame::from_normal(cone.axis);
        let (e1, e2) = (frame.s, frame.t);
        let (sin_a, cos_a) = (2.0 * PI * u.y).sin_cos();
        let around = cos_a * e1 + sin_a * e2;
        let mut x = u.x * total;
        // A zone of a sphere: cos(theta) about the axis uniform in [lo, hi].
        let zone = |centre: Vec3, r: f32, lo: f32, hi: f32, t: f32| {
            let z = lo + t * (hi - lo);
            let d = z * cone.axis + (1.0 - z * z).max(0.0).sqrt() * around;
            (centre + r * d, d)
        };
        if x < start {
            return zone(self.p0, self.r0, -1.0, cone.sin, x / start);
        }
        x -= start;
        if x < body || end == 0.0 {
            // Along the side (length L cos) with density in proportion to the radius,
            // r0 cos - l sin: the root of the quadratic cumulative area.
            let t = (x / body).clamp(0.0, 1.0);
            let (big_r0, big_r1) = (self.r0 * cone.cos, self.r1 * cone.cos);
            let side = cone.len * cone.cos;
            let k = (big_r1 - big_r0) / side;
            let c = t * (big_r0 + big_r1) * side * 0.5;
            let l = 2.0 * c / (big_r0 + (big_r0 * big_r0 + 2.0 * k * c).max(0.0).sqrt());
            let y = self.r0 * cone.sin + l * cone.cos;
            let rho = big_r0 - l * cone.sin;
            let n = cone.sin * cone.axis + cone.cos * around;
            return (self.p0 + y * cone.axis + rho * around, n);
        }
        zone(self.p1, self.r1, cone.sin, 1.0, (x - body) / end)
    }

    pub fn bounds(&self) -> (Vec3, Vec3) {
        (
            (self.p0 - Vec3::splat(self.r0)).min(self.p1 - Vec3::splat(self.r1)),
            (self.p0 + Vec3::splat(self.r0)).max(self.p1 + Vec3::splat(self.r1)),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The signed distance to the convex hull of the two spheres, written from the hull's
    /// definition: the nearer sphere beyond the circles where the cone touches them, the cone
    /// between.
    fn hull_distance(p: &Piece, x: Vec3) -> f32 {
        let w = p.p1 - p.p0;
        let len = w.length();
        let axis = w / len;
        let sin = (p.r0 - p.r1) / len;
        let cos = (1.0 - sin * sin).sqrt();
        let q = x - p.p0;
        let y = q.dot(axis);
        let rho = (q - y * axis).length();
        let coordinate = y * cos - rho * sin;
        if coordinate < 0.0 {
            q.length() - p.r0
        } else if coordinate > len * cos {
            (x - p.p1).length() - p.r1
        } else {
            y * sin + rho * cos - p.r0
        }
    }

    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f32 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
        fn vec(&mut self, scale: f32) -> Vec3 {
            Vec3::new(self.next() - 0.5, self.next() - 0.5, self.next() - 0.5) * 2.0 * scale
        }
    }

    fn pieces() -> [Piece; 3] {
        let closed = |p0, r0, p1, r1| Piece {
            p0,
            r0,
            p1,
            r1,
            next: Vec3::ZERO,
            caps: START_CAP | END_CAP,
        };
        [
            closed(
                Vec3::new(-0.5, 0.1, 0.0),
                0.2,
                Vec3::new(0.6, -0.2, 0.3),
                0.2,
            ),
            closed(
                Vec3::new(-0.4, 0.0, 0.2),
                0.35,
                Vec3::new(0.5, 0.3, -0.1),
                0.1,
            ),
            closed(
                Vec3::new(0.3, -0.3, 0.0),
                0.05,
                Vec3::new(-0.2, 0.4, 0.1),
                0.3,
            ),
        ]
    }

    /// Where rays enter the hull, found by marching its distance function and bisecting,
    /// against the closed form; rays from inside meet nothing; the normal at each hit is the
    /// distance's gradient.
    #[test]
    fn rays_enter_the_hull_of_the_two_spheres() {
        let mut rng = Rng(7);
        for piece in pieces() {
            let (mut hits, mut inside) = (0, 0);
            for _ in 0..4000 {
                let origin = rng.vec(1.2);
                let target = rng.vec(0.4);
                let ray = Ray::new(origin, (target - origin).normalize());
                let found = piece.intersect(&ray, f32::INFINITY);
                if hull_distance(&piece, origin) < 0.0 {
                    inside += 1;
                    assert!(
                        found.is_none(),
                        "{piece:?}: a ray from inside met the piece"
                    );
                    continue;
                }
                // March in steps smaller than any feature, then bisect.
                let (mut t, step) = (0.0f32, 1e-3);
                let expected = loop {
                    if t > 4.0 {
                        break None;
                    }
                    if hull_distance(&piece, ray.at(t + step)) < 0.0 {
                        let (mut lo, mut hi) = (t, t + step);
                        for _ in 0..30 {
                            let mid = 0.5 * (lo + hi);
                            if hull_distance(&piece, ray.at(mid)) < 0.0 {
                                hi = mid;
                            } else {
                                lo = mid;
                            }
                        }
                        break Some(hi);
                    }
                    t += step;
                };
                match (found, expected) {
                    (Some(a), Some(b)) => {
                        hits += 1;
                        assert!((a - b).abs() < 1e-4, "{piece:?}, {ray:?}: {a} against {b}");
                        let p = ray.at(a);
                        let h = 1e-3;
                        let gradient = Vec3::new(
                            hull_distance(&piece, p + h * Vec3::X)
                                - hull_distance(&piece, p - h * Vec3::X),
                            hull_distance(&piece, p + h * Vec3::Y)
                                - hull_distance(&piece, p - h * Vec3::Y),
                            hull_distance(&piece, p + h * Vec3::Z)
                                - hull_distance(&piece, p - h * Vec3::Z),
                        )
                        .normalize();
                        assert!(piece.normal(p).dot(gradient) > 0.999, "{piece:?} at {p}");
                    }
                    (None, None) => {}
                    // A ray grazing the surface may meet it in one and not the other.
                    (a, b) => assert!(
                        {
                            let t = a.or(b).unwrap();
                            hull_distance(&piece, ray.at(t)).abs() < 1e-4
                                && (0..=20).all(|k| {
                                    hull_distance(&piece, ray.at(t + (k as f32 - 10.0) * 1e-3))
                                        > -2e-4
                                })
                        },
                        "{piece:?}, {ray:?}: {a:?} against {b:?}"
                    ),
                }
            }
            assert!(
                hits > 500 && inside > 20,
                "{hits} hits, {inside} from inside"
            );
        }
    }

    /// An open end lets rays through: looking into a tube along its axis from the open
    /// side sees nothing of it; the closed piece is met on its cap.
    #[test]
    fn an_open_end_is_seen_through() {
        let mut piece = Piece {
            p0: Vec3::ZERO,
            r0: 0.2,
            p1: Vec3::X,
            r1: 0.2,
            next: Vec3::ZERO,
            caps: START_CAP | END_CAP,
        };
        let ray = Ray::new(Vec3::new(-1.0, 0.05, 0.0), Vec3::X);
        let t = piece.intersect(&ray, f32::INFINITY).unwrap();
        assert!((ray.at(t) - piece.p0).length() - 0.2 < 1e-5 && t < 1.0);
        piece.caps = 0;
        assert_eq!(piece.intersect(&ray, f32::INFINITY), None);
        // From the side the open tube is hit as the closed one.
        let side = Ray::new(Vec3::new(0.5, 1.0, 0.0), Vec3::NEG_Y);
        assert!((piece.intersect(&side, f32::INFINITY).unwrap() - 0.8).abs() < 1e-5);
    }

    /// Inside a bent tube, seen through its open end: the sphere that joins two pieces does
    /// not reach into the second, so a ray running back down the second piece meets nothing
    /// (it met the sphere's far side before the sphere was cut there).
    #[test]
    fn a_joint_sphere_stops_where_the_next_piece_begins() {
        let angle = 60f32.to_radians();
        let bend = Vec3::new(angle.cos(), angle.sin(), 0.0);
        let first = Piece {
            p0: Vec3::ZERO,
            r0: 0.2,
            p1: Vec3::X,
            r1: 0.2,
            next: bend,
            caps: END_CAP,
        };
        let second = Piece {
            p0: Vec3::X,
            r0: 0.2,
            p1: Vec3::X + bend,
            r1: 0.2,
            next: Vec3::ZERO,
            caps: 0,
        };
        let outward = Vec3::new(angle.sin(), -angle.cos(), 0.0);
        let ray = Ray::new(second.p1 + 0.1 * bend + 0.15 * outward, -bend);
        assert_eq!(first.intersect(&ray, f32::INFINITY), None);
        assert_eq!(second.intersect(&ray, f32::INFINITY), None);
        // The same sphere from outside, on the bend's outer side, is there.
        let elbow = Ray::new(
            Vec3::X + 2.0 * Vec3::new(1.0, -1.0, 0.0).normalize(),
            Vec3::new(-1.0, 1.0, 0.0).normalize(),
        );
        let t = first.intersect(&elbow, f32::INFINITY).expect("the elbow");
        assert!((elbow.at(t).distance(Vec3::X) - 0.2).abs() < 1e-5);
    }

    /// The area is the surface of revolution's, integrated numerically along its profile;
    /// sampled points lie on the surface, with its normal there, in each part as often as
    /// its share of the area.
    #[test]
    fn sampling_is_uniform_over_the_surface() {
        let mut rng = Rng(3);
        for piece in pieces() {
            // The profile in (y, rho): arc of the first sphere, the line, arc of the second.
            let w = piece.p1 - piece.p0;
            let len = w.length();
            let sin = (piece.r0 - piece.r1) / len;
            let phi = sin.asin();
            let n = 20000;
            let mut area = 0.0f64;
            let arc = |c: f32, r: f32, from: f32, to: f32, area: &mut f64| {
                for k in 0..n {
                    let a = from + (to - from) * (k as f32 + 0.5) / n as f32;
                    let rho = r * a.sin();
                    *area += 2.0 * PI as f64 * rho as f64 * (r * (to - from) / n as f32) as f64;
                    let _ = c;
                }
            };
            // Angle from the -axis pole of the first sphere up to its circle: pi/2 + phi.
            arc(0.0, piece.r0, 0.0, PI / 2.0 + phi, &mut area);
            arc(len, piece.r1, 0.0, PI / 2.0 - phi, &mut area);
            let (a, b) = (piece.r0 * phi.cos(), piece.r1 * phi.cos());
            let slant = len * phi.cos();
            area += PI as f64 * (a + b) as f64 * slant as f64;
            assert!(
                (piece.area() as f64 - area).abs() < 1e-3 * area,
                "{} against {area}",
                piece.area()
            );
            let (mut on_start, mut on_end) = (0, 0);
            let m = 40000;
            for _ in 0..m {
                let (p, normal) = piece.sample_area(Vec2::new(rng.next(), rng.next()));
                assert!(hull_distance(&piece, p).abs() < 1e-5, "{p} off the surface");
                assert!((piece.normal(p) - normal).length() < 1e-3);
                let q = p - piece.p0;
                let y = q.dot(w / len);
                let coordinate = y * phi.cos() - (q - y * w / len).length() * sin;
                if coordinate < 0.0 {
                    on_start += 1;
                } else if coordinate > len * phi.cos() {
                    on_end += 1;
                }
            }
            let start = 2.0 * PI * piece.r0 * piece.r0 * (1.0 + sin) / piece.area();
            let end = 2.0 * PI * piece.r1 * piece.r1 * (1.0 - sin) / piece.area();
            for (count, share) in [(on_start, start), (on_end, end)] {
                let sigma = (share * (1.0 - share) / m as f32).sqrt();
                assert!(
                    (count as f32 / m as f32 - share).abs() < 4.0 * sigma + 1e-4,
                    "{count} of {m} against a share of {share}"
                );
            }
        }
    }

    /// dp/du and dp/dv are the derivatives of the parameterisation: a small step along
    /// either, put back on the surface, moves (u, v) by that step in u or v alone.
    #[test]
    fn tangents_are_the_derivatives_of_the_texture_coordinates() {
        let mut rng = Rng(11);
        for piece in pieces() {
            for _ in 0..200 {
                let (p, n) = piece.sample_area(Vec2::new(rng.next(), rng.next()));
                let (uv, dpdu, dpdv) = piece.surface(p, n, 0.25, 0.5);
                // Away from u's seam, and on the cone: a cap has one v.
                if !(0.1..0.9).contains(&uv.x) || !(0.2501..0.4999).contains(&uv.y) {
                    continue;
                }
                let h = 1e-3;
                for (tangent, step) in [(dpdu, Vec2::X), (dpdv, Vec2::Y)] {
                    let mut q = p + h * tangent;
                    q -= hull_distance(&piece, q) * piece.normal(q);
                    let (moved, _, _) = piece.surface(q, piece.normal(q), 0.25, 0.5);
                    let duv = (moved - uv) / h;
                    // v stops at the ends of the cone (the caps have one v each).
                    if (moved.y - 0.25).abs() < 1e-6 || (moved.y - 0.5).abs() < 1e-6 {
                        continue;
                    }
                    assert!(
                        (duv - step).length() < 2e-2,
                        "{piece:?} at {p}: a step along the tangent of {step} moved uv by {duv}"
                    );
                }
            }
        }
    }
}
