//! Curve files (Mitsuba 3's `linearcurve` and `bsplinecurve`) into pieces of round curves
//! ([`foton_core::geometry::curve`]).
//!
//! The file holds one control point per line, `x y z r` (anything after the fourth number is
//! ignored); a blank line ends a curve and the next point starts another. Points are moved by
//! the shape's transform, radii are not: Mitsuba 3's convention.
//!
//! A linear curve of n points is n - 1 pieces, each a cone between its points' spheres, joined
//! by those spheres and closed by them at both ends (Embree's round linear curve). A B-spline
//! curve of n points is n - 3 spans of the uniform cubic B-spline, in position and radius alike;
//! Embree sweeps a circle along it, open at the curve's ends. foton follows each span with a
//! chain of pieces fine enough that the chord strays from the spline by at most
//! [`CHORD_TOLERANCE`] of the radius (the circle sweep and the chain of spheres are the same
//! tube where the radius is constant, as in every published scene), open at the curve's ends.
//! The texture coordinate v runs from 0 to 1 over all segments (spans) of the file, as
//! Mitsuba's does; u goes round the curve.

use foton_core::geometry::Shape;
use foton_core::geometry::curve::{END_CAP, START_CAP};
use glam::{Mat4, Vec3};

/// How far a B-spline's chain of pieces may stray from the curve: a fraction of its radius.
pub const CHORD_TOLERANCE: f32 = 1e-3;

/// The most pieces a B-spline span becomes.
const MAX_PIECES: usize = 256;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Basis {
    Linear,
    BSpline,
}

/// Control points (x, y, z, radius) of the curves in a file, one list per curve, as written;
/// or the 1-based line and what is wrong with it.
pub fn parse(text: &str, basis: Basis) -> Result<Vec<Vec<[f32; 4]>>, (usize, String)> {
    let mut curves: Vec<Vec<[f32; 4]>> = Vec::new();
    let mut open = false;
    for (i, line) in text.lines().enumerate() {
        let trimmed = line.trim();
        if trimmed.is_empty() {
            open = false;
            continue;
        }
        let mut numbers = trimmed.split_whitespace().map(str::parse::<f32>);
        let mut point = [0.0f32; 4];
        for (k, value) in point.iter_mut().enumerate() {
            match numbers.next() {
                Some(Ok(x)) if x.is_finite() => *value = x,
                Some(Ok(x)) => return Err((i + 1, format!("value {} is {x}", k + 1))),
                _ => {
                    return Err((
                        i + 1,
                        format!("expected four numbers `x y z radius`, found {trimmed:?}"),
                    ));
                }
            }
        }
        if point[3] < 0.0 {
            return Err((
                i + 1,
                format!("the radius must not be negative, found {}", point[3]),
            ));
        }
        if !open {
            curves.push(Vec::new());
            open = true;
        }
        curves.last_mut().unwrap().push(point);
    }
    let least = match basis {
        Basis::Linear => 2,
        Basis::BSpline => 4,
    };
    if let Some(short) = curves.iter().position(|c| c.len() < least) {
        return Err((
            0,
            format!(
                "curve {} has {} control point(s); a {} curve needs at least {least}",
                short + 1,
                curves[short].len(),
                match basis {
                    Basis::Linear => "linear",
                    Basis::BSpline => "B-spline",
                }
            ),
        ));
    }
    if curves.is_empty() {
        return Err((0, "the file holds no control point".into()));
    }
    Ok(curves)
}

/// The pieces of the curves, their points moved by `transform`, their radii times
/// `radius_scale`.
pub fn pieces(
    curves: &[Vec<[f32; 4]>],
    basis: Basis,
    transform: Mat4,
    radius_scale: f32,
) -> Vec<Shape> {
    let moved: Vec<Vec<(Vec3, f32)>> = curves
        .iter()
        .map(|c| {
            c.iter()
                .map(|p| {
                    (
                        transform.transform_point3(Vec3::new(p[0], p[1], p[2])),
                        p[3] * radius_scale,
                    )
                })
                .collect()
        })
        .collect();
    let per_curve = |c: &Vec<(Vec3, f32)>| match basis {
        Basis::Linear => c.len() - 1,
        Basis::BSpline => c.len() - 3,
    };
    let segments: usize = moved.iter().map(per_curve).sum();
    let v_of = |segment: usize, t: f32| (segment as f32 + t) / segments as f32;
    let mut shapes = Vec::new();
    let mut first = 0;
    for c in &moved {
        let n = per_curve(c);
        let start = shapes.len();
        for k in 0..n {
            let segment = first + k;
            match basis {
                Basis::Linear => {
                    let ((p0, r0), (p1, r1)) = (c[k], c[k + 1]);
                    let caps = END_CAP | if k == 0 { START_CAP } else { 0 };
                    shapes.push(Shape::Curve {
                        p0,
                        r0,
                        p1,
                        r1,
                        v0: v_of(segment, 0.0),
                        v1: v_of(segment, 1.0),
                        next: Vec3::ZERO,
                        caps,
                    });
                }
                Basis::BSpline => {
                    let span = [c[k], c[k + 1], c[k + 2], c[k + 3]];
                    let count = pieces_of(&span);
                    let at = |t: f32| {
                        let w = bspline_weights(t);
                        span.iter()
                            .zip(w)
                            .fold((Vec3::ZERO, 0.0), |(p, r), (&(q, s), w)| {
                                (p + w * q, r + w * s)
                            })
                    };
                    for j in 0..count {
                        let t = |j: usize| j as f32 / count as f32;
                        let ((p0, r0), (p1, r1)) = (at(t(j)), at(t(j + 1)));
                        // Spheres join the pieces; the curve's own ends stay open.
                        let last = k + 1 == n && j + 1 == count;
                        shapes.push(Shape::Curve {
                            p0,
                            r0,
                            p1,
                            r1,
                            v0: v_of(segment, t(j)),
                            v1: v_of(segment, t(j + 1)),
                            next: Vec3::ZERO,
                            caps: if last { 0 } else { END_CAP },
                        });
                    }
                }
            }
        }
        // Each piece of the curve learns the direction of the one after it.
        for i in start + 1..shapes.len() {
            if let Shape::Curve { p0, p1, .. } = shapes[i]
                && let Shape::Curve { next, .. } = &mut shapes[i - 1]
            {
                *next = (p1 - p0).normalize_or_zero();
            }
        }
        first += n;
    }
    shapes
}

/// The uniform cubic B-spline's weights of a span's four control points at t in [0, 1].
fn bspline_weights(t: f32) -> [f32; 4] {
    let s = 1.0 - t;
    [
        s * s * s / 6.0,
        (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0,
        (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
        t * t * t / 6.0,
    ]
}

/// Pieces for a span: a chord over a parameter step h strays at most h^2 max|C''| / 8 from
/// the curve, and |C''| is at most the larger second difference of the control points.
fn pieces_of(span: &[(Vec3, f32); 4]) -> usize {
    let second = |a: usize| (span[a].0 - 2.0 * span[a + 1].0 + span[a + 2].0).length();
    let curvature = second(0).max(second(1));
    let radius = span.iter().map(|p| p.1).fold(f32::INFINITY, f32::min);
    let tolerance = CHORD_TOLERANCE * radius.max(1e-6 * (1.0 + span[0].0.abs().max_element()));
    let count = (curvature / (8.0 * tolerance)).sqrt().ceil();
    (count as usize).clamp(4, MAX_PIECES)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blank_lines_separate_curves_and_bad_lines_are_reported() {
        let text = "0 0 0 0.1\n  1 0 0 0.1 extra\n\n\n2 0 0 0.2\n3 0 0 0.2\n";
        let curves = parse(text, Basis::Linear).unwrap();
        assert_eq!(curves.len(), 2);
        assert_eq!(curves[0][1], [1.0, 0.0, 0.0, 0.1]);
        assert_eq!(curves[1][0], [2.0, 0.0, 0.0, 0.2]);
        assert_eq!(parse("0 0 0\n", Basis::Linear).unwrap_err().0, 1);
        assert_eq!(parse("0 0 0 1\n# x\n", Basis::Linear).unwrap_err().0, 2);
        let short = parse(text, Basis::BSpline).unwrap_err().1;
        assert!(short.contains("at least 4"), "{short}");
    }

    /// Linear pieces join the control points with their radii, capped at the curve's first
    /// point and at every joint; v runs over all segments of the file.
    #[test]
    fn linear_curves_are_their_segments() {
        let curves = parse(
            "0 0 0 0.1\n1 0 0 0.2\n1 1 0 0.1\n\n5 5 5 1\n6 5 5 1\n",
            Basis::Linear,
        )
        .unwrap();
        let shapes = pieces(
            &curves,
            Basis::Linear,
            Mat4::from_scale(Vec3::splat(2.0)),
            1.0,
        );
        assert_eq!(shapes.len(), 3);
        let Shape::Curve {
            p0,
            r0,
            p1,
            r1,
            v0,
            v1,
            next,
            caps,
        } = shapes[1]
        else {
            panic!()
        };
        assert_eq!(
            (p0, p1),
            (Vec3::new(2.0, 0.0, 0.0), Vec3::new(2.0, 2.0, 0.0))
        );
        // Radii are not scaled.
        assert_eq!((r0, r1), (0.2, 0.1));
        assert_eq!((v0, v1), (1.0 / 3.0, 2.0 / 3.0));
        assert_eq!(caps, END_CAP);
        // The last of its curve: nothing after it.
        assert_eq!(next, Vec3::ZERO);
        assert!(matches!(shapes[0], Shape::Curve { next: Vec3::Y, .. }));
        assert!(matches!(shapes[2], Shape::Curve { caps: 3, .. }));
    }

    /// The chain of pieces follows the uniform cubic B-spline: its joints lie on the curve
    /// (written out as the matrix form), within the tolerance of it in between; the ends are
    /// open.
    #[test]
    fn bspline_pieces_follow_the_spline() {
        let points = [
            [0.0, 0.0, 0.0, 0.05],
            [1.0, 2.0, 0.0, 0.05],
            [2.0, -1.0, 0.5, 0.05],
            [3.0, 1.0, 0.0, 0.05],
            [4.0, 0.0, 1.0, 0.05],
        ];
        let shapes = pieces(&[points.to_vec()], Basis::BSpline, Mat4::IDENTITY, 1.0);
        let p = |i: usize| Vec3::new(points[i][0], points[i][1], points[i][2]);
        // (1/6) [t^3 t^2 t 1] M [P0..P3] with the standard basis matrix.
        let curve = |span: usize, t: f32| {
            let m = [
                [-1.0, 3.0, -3.0, 1.0],
                [3.0, -6.0, 3.0, 0.0],
                [-3.0, 0.0, 3.0, 0.0],
                [1.0, 4.0, 1.0, 0.0],
            ];
            let powers = [t * t * t, t * t, t, 1.0];
            (0..4).fold(Vec3::ZERO, |acc, j| {
                let w: f32 = (0..4).map(|i| powers[i] * m[i][j]).sum();
                acc + w / 6.0 * p(span + j)
            })
        };
        let mut last_v = 0.0;
        for (i, s) in shapes.iter().enumerate() {
            let Shape::Curve {
                p0,
                p1,
                v0,
                v1,
                caps,
                ..
            } = *s
            else {
                panic!()
            };
            let (span, t0) = ((v0 * 2.0).floor() as usize, (v0 * 2.0).fract());
            assert!((curve(span, t0) - p0).length() < 1e-5);
            let mid = curve(span, (t0 + (v1 * 2.0 - span as f32)) * 0.5);
            let chord = 0.5 * (p0 + p1);
            assert!((mid - chord).length() <= 0.05 * CHORD_TOLERANCE * 1.5 + 1e-6);
            assert!((v0 - last_v).abs() < 1e-6);
            last_v = v1;
            assert_eq!(caps, if i + 1 == shapes.len() { 0 } else { END_CAP });
            // Each piece knows the direction of the one after it.
            match shapes.get(i + 1) {
                Some(&Shape::Curve { p0: q0, p1: q1, .. }) => {
                    let Shape::Curve { next, .. } = *s else {
                        panic!()
                    };
                    assert!((next - (q1 - q0).normalize()).length() < 1e-4, "{i}");
                }
                _ => assert!(matches!(
                    *s,
                    Shape::Curve {
                        next: Vec3::ZERO,
                        ..
                    }
                )),
            }
        }
        assert!((last_v - 1.0).abs() < 1e-6);
    }

    /// Mutated curve files (bytes, numbers, lines changed): an error with a line or pieces,
    /// never a panic, and the pieces answer rays without one. FOTON_FUZZ_CURVE cases (2000).
    #[test]
    fn mutated_curve_files_are_errors_or_curves() {
        use crate::mutations::{Cases, count, mutate};
        use foton_core::geometry::Ray;
        let base = "0 0 0 0.1\n1 0 0.5 0.1\n2 1 0 0.2\n3 0 0 0.05\n\n0 2 0 0.3\n1 2 1 0.3\n";
        let n = count("FOTON_FUZZ_CURVE", 2000);
        let mut cases = Cases::new(17);
        let mut outcomes = [0usize; 2];
        for _ in 0..n {
            let text = mutate(base, b"0123456789 .-e\n#", &mut cases);
            let basis = if cases.below(2) == 0 {
                Basis::Linear
            } else {
                Basis::BSpline
            };
            let run = std::panic::catch_unwind(|| {
                let curves = parse(&text, basis)?;
                for shape in pieces(&curves, basis, Mat4::from_scale(Vec3::splat(1.5)), 1.0) {
                    let _ = shape.aabb();
                    for dir in [Vec3::X, Vec3::NEG_Z, Vec3::new(1.0, 1.0, 1.0).normalize()] {
                        let ray = Ray::new(Vec3::splat(-5.0) + Vec3::Y * 5.0, dir);
                        if let Some(t) = shape.intersect(&ray, f32::INFINITY) {
                            let p = ray.at(t);
                            let n = shape.normal(p);
                            let _ = shape.surface_at(p, n, None, None, true);
                        }
                    }
                }
                Ok::<_, (usize, String)>(())
            });
            match run {
                Ok(r) => outcomes[r.is_ok() as usize] += 1,
                Err(_) => panic!("panicked on:\n{text}"),
            }
        }
        assert!(
            outcomes[0] > n / 10 && outcomes[1] > n / 10,
            "errors, curves: {outcomes:?}"
        );
    }
}
