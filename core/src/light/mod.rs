//! Lights: point, spot, projector, collimated and area lights (any emissive shape), and lights
//! at infinity (directional, constant and environment-mapped), one file per kind, each listed
//! on one line of the `lights!` invocation below.
//!
//! A kind implements [`LightSource`]; [`Light`] is the tagged union of the kinds (pbrt-v4's
//! `Light`), which the integrators hold and call without a virtual call, since light
//! sampling is in their innermost loops; [`LIGHTS`] is the table of their factories, which
//! the scene reader looks a `[[lights]]` entry's `type` up in.

use crate::Rgb;
use crate::registry::Factory;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

lights! {
    /// A light of any kind: one variant per file of this folder.
    #[derive(Clone, Debug)]
    pub enum Light {
        Point(point::PointLight),
        Spot(spot::SpotLight),
        Directional(directional::DirectionalLight),
        Constant(constant::ConstantLight),
        Envmap(envmap::EnvmapLight),
        Area(area::AreaLight),
        SunSky(sunsky::SunSkyLight),
        Projector(projector::ProjectorLight),
        Collimated(collimated::CollimatedLight),
    }
}

pub use area::area_light;
pub use spot::{Falloff, smoothstep, spot_falloff, spot_solid_angle};

/// What is singular about a light (pbrt-v4's `LightType`): its position (a point or spot
/// light), its direction (a directional light), neither (an area light), or that it lies
/// infinitely far in every direction (an environment).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightType {
    DeltaPosition,
    DeltaDirection,
    /// A delta in both (a collimated beam): next-event estimation never reaches it.
    DeltaBeam,
    Area,
    Infinite,
}

/// One kind of light: what [`Light`] dispatches to. Radiometric conventions are those of
/// [`LightSample`] and [`EmittedRay`].
pub trait LightSource {
    fn light_type(&self) -> LightType;

    /// Total emitted power in W (for a light at infinity, the flux through the disc of the
    /// scene's bounding sphere).
    fn power(&self) -> Rgb;

    /// Samples a direction from `x` towards the light (`u`: on the light, `uc`: which part
    /// of it).
    fn sample_li(&self, x: Vec3, u: Vec2, uc: f32) -> Option<LightSample>;

    /// Solid-angle pdf with which `sample_li` from `x` produces the point `p` (normal `n`)
    /// on this light; needed for MIS when a BSDF-sampled ray hits the light. Zero for a
    /// delta light.
    fn pdf_li(&self, x: Vec3, p: Vec3, n: Vec3) -> f32;

    /// Samples a photon leaving the light.
    fn sample_emission(&self, u_pos: Vec2, u_dir: Vec2, uc: f32) -> EmittedRay;

    /// The densities with which [`LightSource::sample_emission`] emits a ray along `dir`
    /// (unit) from a point with normal `n` on the light (pbrt-v4's `PDF_Le`): (per unit area
    /// of where it starts, per solid angle of its direction). A point or spot light's
    /// position is a delta (1); a directional light's direction is (1). A light at infinity
    /// starts its rays on the disc of the scene's bounding sphere facing `dir`, whatever the
    /// origin. Zero for what the light never emits (behind an area light, outside a spot's
    /// cone).
    fn pdf_le(&self, n: Vec3, dir: Vec3) -> (f32, f32);

    /// Radiance leaving the light at a point with normal `n` and texture coordinates `uv`
    /// in direction `w` (an area light's; zero for the others).
    fn emitted(&self, _n: Vec3, _uv: Vec2, _w: Vec3) -> Rgb {
        Rgb::ZERO
    }

    /// Radiance arriving from infinitely far along -`dir` (a ray travelling along `dir` that
    /// leaves the scene): an environment's; zero for the others.
    fn environment(&self, _dir: Vec3) -> Rgb {
        Rgb::ZERO
    }

    /// Where the light is, for the scene's bounds (a point or spot light).
    fn position(&self) -> Option<Vec3> {
        None
    }

    /// For a light at infinity: the scene's bounding sphere, which its power and its
    /// photons' origins need. Other lights ignore it.
    fn fit_to_scene(&mut self, _sphere: SceneSphere) {}
}

/// Declares the light kinds' files and the [`Light`] union over them, one line per kind:
/// the variant `Variant(file::Type)` declares `pub mod file;` (which defines `Type`,
/// implementing [`LightSource`], and `pub const FACTORY: Factory<Type>`), re-exports `Type`,
/// and adds the factory to [`LIGHTS`] and the variant to `Light`'s methods, which dispatch
/// to the kind's [`LightSource`] implementation.
macro_rules! lights {
    (
        $(#[$attr:meta])*
        pub enum Light { $($variant:ident($module:ident::$kind:ident)),* $(,)? }
    ) => {
        $(pub mod $module;)*
        $(pub use $module::$kind;)*

        $(#[$attr])*
        pub enum Light {
            $($variant($module::$kind),)*
        }

        /// The built-in lights: a `[[lights]]` entry's `type` is looked up here.
        pub const LIGHTS: &[Factory<Light>] = &[$(Factory {
            name: $module::FACTORY.name,
            description: $module::FACTORY.description,
            create: |bag, nested, resources| {
                let light = ($module::FACTORY.create)(bag, nested, resources)?;
                Ok(Box::new(Light::$variant(*light)))
            },
        }),*];

        $(impl From<$kind> for Light {
            fn from(light: $kind) -> Light {
                Light::$variant(light)
            }
        })*

        impl Light {
            /// See [`LightSource::light_type`].
            #[inline]
            pub fn light_type(&self) -> LightType {
                match self {
                    $(Light::$variant(l) => l.light_type(),)*
                }
            }

            /// See [`LightSource::power`].
            pub fn power(&self) -> Rgb {
                match self {
                    $(Light::$variant(l) => l.power(),)*
                }
            }

            /// See [`LightSource::sample_li`].
            #[inline(always)]
            pub fn sample_li(&self, x: Vec3, u: Vec2, uc: f32) -> Option<LightSample> {
                match self {
                    $(Light::$variant(l) => l.sample_li(x, u, uc),)*
                }
            }

            /// See [`LightSource::pdf_li`].
            pub fn pdf_li(&self, x: Vec3, p: Vec3, n: Vec3) -> f32 {
                match self {
                    $(Light::$variant(l) => l.pdf_li(x, p, n),)*
                }
            }

            /// See [`LightSource::sample_emission`].
            pub fn sample_emission(&self, u_pos: Vec2, u_dir: Vec2, uc: f32) -> EmittedRay {
                match self {
                    $(Light::$variant(l) => l.sample_emission(u_pos, u_dir, uc),)*
                }
            }

            /// See [`LightSource::pdf_le`].
            pub fn pdf_le(&self, n: Vec3, dir: Vec3) -> (f32, f32) {
                match self {
                    $(Light::$variant(l) => l.pdf_le(n, dir),)*
                }
            }

            /// See [`LightSource::emitted`].
            #[inline]
            pub fn emitted(&self, n: Vec3, uv: Vec2, w: Vec3) -> Rgb {
                match self {
                    $(Light::$variant(l) => l.emitted(n, uv, w),)*
                }
            }

            /// See [`LightSource::environment`].
            #[inline]
            pub fn environment(&self, dir: Vec3) -> Rgb {
                match self {
                    $(Light::$variant(l) => l.environment(dir),)*
                }
            }

            /// See [`LightSource::position`].
            pub fn position(&self) -> Option<Vec3> {
                match self {
                    $(Light::$variant(l) => l.position(),)*
                }
            }

            /// Sets the bounding sphere of a light at infinity (see
            /// [`LightSource::fit_to_scene`]).
            pub fn fit_to_scene(&mut self, centre: Vec3, radius: f32) {
                match self {
                    $(Light::$variant(l) => l.fit_to_scene(SceneSphere { centre, radius }),)*
                }
            }

            /// The name of the light's kind in scene files (`point`, `area`...).
            pub fn name(&self) -> &'static str {
                match self {
                    $(Light::$variant(_) => $module::FACTORY.name,)*
                }
            }
        }
    };
}
use lights;

impl Light {
    /// A point, spot, directional or collimated light: a delta in position or direction.
    #[inline]
    pub fn is_delta(&self) -> bool {
        matches!(
            self.light_type(),
            LightType::DeltaPosition | LightType::DeltaDirection | LightType::DeltaBeam
        )
    }

    /// Whether rays that leave the scene see this light (a constant or an environment map:
    /// a scene has at most one).
    #[inline]
    pub fn is_environment(&self) -> bool {
        self.light_type() == LightType::Infinite
    }

    /// Whether the light is infinitely far (directional, constant, environment map): its
    /// rays start on the scene's bounding disc, and a distance to it means nothing.
    #[inline]
    pub fn is_infinite(&self) -> bool {
        matches!(
            self.light_type(),
            LightType::DeltaDirection | LightType::Infinite
        )
    }

    /// Whether [`Light::emitted`] reads its texture coordinates (an area light whose
    /// radiance is a texture): the others need not be computed.
    #[inline]
    pub fn needs_uv(&self) -> bool {
        matches!(self, Light::Area(a) if a.texture.as_ref().is_some_and(|t| t.texture.is_some()))
    }

    /// The opacity at `uv` of a cut-out area light (1 for every other light): a point the
    /// light sampled emits [`Light::emitted`] times it (a ray that meets the surface has
    /// passed the cut-out's test already).
    #[inline]
    pub fn opacity(&self, uv: Vec2) -> f32 {
        match self {
            Light::Area(a) => a.opacity(uv),
            _ => 1.0,
        }
    }
}

/// A light sample seen from a receiving point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the receiver towards the light.
    pub wi: Vec3,
    pub dist: f32,
    /// Incident radiance (area light) or intensity / dist^2 (point light), unoccluded.
    pub li: Rgb,
    /// Solid-angle pdf of this sample given the light was chosen; 1 for a point light.
    pub pdf: f32,
    pub delta: bool,
    /// The point on the light and its normal (for offsetting the shadow ray's end).
    pub p: Vec3,
    pub n: Vec3,
}

/// A photon leaving a light.
#[derive(Clone, Copy, Debug)]
pub struct EmittedRay {
    pub origin: Vec3,
    pub dir: Vec3,
    /// Normal at the origin (zero for a point light).
    pub n: Vec3,
    /// Le cos / (pdf_pos pdf_dir): the flux carried by one emitted sample (before dividing by
    /// the number of samples and the light-selection probability).
    pub flux: Rgb,
    /// Texture coordinates at the origin (a textured area light's; zero for the others).
    pub uv: Vec2,
    /// What leaves along `dir`: radiance (area lights, lights at infinity: per unit area of
    /// the disc they are emitted from; for a directional light, its irradiance) or intensity
    /// (point and spot lights).
    pub le: Rgb,
    /// The densities of the sample, as [`Light::pdf_le`] gives them: of the origin (per unit
    /// area; 1 for a point or spot light) and of the direction (per solid angle; 1 for a
    /// directional light, whose direction is fixed).
    pub pdf_pos: f32,
    pub pdf_dir: f32,
}

/// The scene's bounding sphere, which a light at infinity covers: its photons start on the
/// disc of the sphere facing their direction, and its power is the flux through that disc.
/// Set once the scene is loaded ([`Light::fit_to_scene`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SceneSphere {
    pub centre: Vec3,
    pub radius: f32,
}

impl SceneSphere {
    /// The area of a great disc, pi R^2.
    #[inline]
    pub fn disc_area(&self) -> f32 {
        PI * self.radius * self.radius
    }

    /// A light sample from infinitely far along `wi` (a delta direction with unit pdf, to be
    /// adjusted by the caller): the shadow ray ends past the sphere.
    pub fn sample_at_infinity(&self, x: Vec3, wi: Vec3) -> LightSample {
        let dist = 2.0 * self.radius + x.distance(self.centre);
        LightSample {
            wi,
            dist,
            li: Rgb::ZERO,
            pdf: 1.0,
            delta: true,
            p: x + wi * dist,
            n: Vec3::ZERO,
        }
    }

    /// Where a photon from infinitely far, travelling along `dir`, starts: a uniform point of
    /// the disc facing it, just outside the sphere (pbrt's distant light).
    pub fn disc_origin(&self, dir: Vec3, u: Vec2) -> Vec3 {
        let d = crate::sampling::concentric_disc(u) * self.radius;
        let (s, t) = crate::sampling::basis(dir);
        self.centre - dir * self.radius + s * d.x + t * d.y
    }
}

/// The direction from `x` to `p`, the distance and its square (a point light's 1/r^2); None
/// when they coincide.
#[inline(always)]
/// The unit axis of a light at `position` aimed by `look_at` or `direction` (exactly one):
/// `what` names the light in the error of neither ("a spot light").
fn read_axis(
    l: &crate::props::Properties<'_>,
    position: Vec3,
    what: &str,
) -> crate::error::Result<Vec3> {
    let axis = match (l.vec3_opt("look_at")?, l.vec3_opt("direction")?) {
        (Some(target), None) => target - position,
        (None, Some(d)) => d,
        (Some(_), Some(_)) => {
            return Err(l.error("direction", "give either look_at or direction, not both"));
        }
        (None, None) => {
            return Err(l.error(
                "look_at",
                format!("missing; {what} needs look_at = [x, y, z] or direction = [x, y, z]"),
            ));
        }
    };
    if axis.length_squared() == 0.0 {
        let key = if l.has("look_at") {
            "look_at"
        } else {
            "direction"
        };
        return Err(l.error(key, "gives no direction (zero length)"));
    }
    Ok(axis.normalize())
}

fn towards(x: Vec3, p: Vec3) -> Option<(Vec3, f32, f32)> {
    let d = p - x;
    let dist2 = d.length_squared();
    if dist2 == 0.0 {
        return None;
    }
    let dist = dist2.sqrt();
    Some((d / dist, dist, dist2))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Shape;
    use crate::sampling::{Rng, uniform_sphere};

    fn lights() -> Vec<(&'static str, Light)> {
        let mut out = vec![
            (
                "point",
                Light::Point(PointLight {
                    position: Vec3::new(0.1, 0.2, 0.3),
                    intensity: Rgb::new(1.0, 2.0, 3.0),
                }),
            ),
            (
                "spot",
                Light::Spot(SpotLight {
                    position: Vec3::ZERO,
                    axis: Vec3::new(0.3, -1.0, 0.2).normalize(),
                    intensity: Rgb::splat(2.0),
                    beam_width: 0.3,
                    cutoff: 0.6,
                    falloff: Falloff::Linear,
                    texture: None,
                }),
            ),
            (
                "directional",
                Light::Directional(DirectionalLight {
                    direction: Vec3::new(0.2, -1.0, 0.1).normalize(),
                    irradiance: Rgb::splat(3.0),
                    sphere: SceneSphere {
                        centre: Vec3::ONE,
                        radius: 2.0,
                    },
                }),
            ),
            (
                "constant",
                Light::Constant(ConstantLight {
                    radiance: Rgb::splat(0.5),
                    sphere: SceneSphere {
                        centre: Vec3::ZERO,
                        radius: 3.0,
                    },
                }),
            ),
        ];
        let quad = Shape::quad(
            Vec3::new(-0.5, 1.0, -0.5),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        );
        let tri = Shape::Triangle {
            p0: Vec3::ZERO,
            e1: Vec3::X,
            e2: Vec3::new(0.3, 0.0, 2.0),
        };
        let mut inward = Shape::sphere(Vec3::new(0.0, 2.0, 0.0), 0.5);
        inward.flip();
        for (name, shapes) in [
            ("area quad", vec![quad]),
            ("area quad + triangle", vec![quad, tri]),
            ("area sphere", vec![Shape::sphere(Vec3::ZERO, 0.7)]),
            ("area inward sphere", vec![inward]),
            (
                "area disk",
                vec![Shape::disk(Vec3::ZERO, Vec3::X * 0.4, Vec3::Z * 0.4)],
            ),
        ] {
            out.push((name, area_light(shapes, Rgb::new(2.0, 1.0, 0.5), 0)));
        }
        out
    }

    /// Each kind answers to its table entry's name, and the table's factories build the
    /// kind they are listed with: a `[[lights]]` point light equals one built directly.
    #[test]
    fn the_table_builds_the_kinds_it_names() {
        use crate::registry::{NoResources, find};
        use crate::value::{Node, Table, Value};
        for (what, light) in lights() {
            assert!(find(LIGHTS, light.name()).is_some(), "{what}");
        }
        let at = |value| Node {
            value,
            line: 1,
            column: 1,
        };
        let v3 = |x: f64, y: f64, z: f64| {
            at(Value::Array(vec![
                at(Value::Float(x)),
                at(Value::Float(y)),
                at(Value::Float(z)),
            ]))
        };
        let table = at(Value::Table(Table(vec![
            ("position".into(), v3(0.1, 0.2, 0.3)),
            ("intensity".into(), v3(1.0, 2.0, 3.0)),
        ])));
        let bag =
            crate::props::Properties::new(std::path::Path::new("t.toml"), "l", &table).unwrap();
        let light =
            (find(LIGHTS, "point").unwrap().create)(&bag, &mut Vec::new(), &mut NoResources)
                .unwrap();
        let Light::Point(p) = *light else {
            panic!("`point` built {light:?}");
        };
        assert_eq!(
            (p.position, p.intensity),
            (Vec3::new(0.1, 0.2, 0.3), Rgb::new(1.0, 2.0, 3.0))
        );
        // An area light is a shape's emission, and says so.
        let e = (find(LIGHTS, "area").unwrap().create)(&bag, &mut Vec::new(), &mut NoResources)
            .unwrap_err()
            .to_string();
        assert!(e.contains("emission"), "{e}");
    }

    /// `sample_emission` reports the densities `pdf_le` gives for its ray, and its flux is
    /// Le cos / (pdf_pos pdf_dir).
    #[test]
    fn emission_pdfs_match_the_samples() {
        let mut rng = Rng::new(&[3]);
        for (name, light) in lights() {
            for _ in 0..2000 {
                let e = light.sample_emission(rng.next_2d(), rng.next_2d(), rng.next_f32());
                let (pos, dir) = light.pdf_le(e.n, e.dir);
                assert!(
                    (pos - e.pdf_pos).abs() <= 1e-5 * pos,
                    "{name}: {pos} {}",
                    e.pdf_pos
                );
                assert!(
                    (dir - e.pdf_dir).abs() <= 2e-4 * dir,
                    "{name}: {dir} {}",
                    e.pdf_dir
                );
                let cos = if e.n == Vec3::ZERO {
                    1.0
                } else {
                    e.n.dot(e.dir)
                };
                if e.pdf_dir > 0.0 {
                    let flux = e.le * (cos / (e.pdf_pos * e.pdf_dir));
                    assert!(
                        (flux - e.flux).abs().max_element() <= 1e-3 * e.flux.max_element(),
                        "{name}: {flux} {}",
                        e.flux
                    );
                }
            }
        }
    }

    /// The direction density integrates to one over the sphere (Monte Carlo with uniform
    /// directions), from any point of an area light; and the emitted power it implies,
    /// the integral of Le cos over directions and area, is `power()`.
    #[test]
    fn emission_direction_pdfs_integrate_to_one() {
        let mut rng = Rng::new(&[5]);
        let n = 200_000;
        for (name, light) in lights() {
            if matches!(light, Light::Directional(_)) {
                continue; // a delta direction
            }
            let e = light.sample_emission(rng.next_2d(), rng.next_2d(), rng.next_f32());
            let mut sum = 0.0f64;
            for _ in 0..n {
                let w = uniform_sphere(rng.next_2d());
                sum += light.pdf_le(e.n, w).1 as f64;
            }
            let integral = sum * 4.0 * std::f64::consts::PI / n as f64;
            assert!((integral - 1.0).abs() < 0.02, "{name}: {integral}");
        }
    }
}
