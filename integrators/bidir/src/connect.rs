//! The connection strategies: t = 1 (a light vertex, or a light subpath's origin, connected
//! to the pinhole and splatted), s = 1 (next-event estimation) and s, t >= 2 (a light vertex
//! connected with a camera vertex), each weighted in O(1) by the power heuristic.

use crate::mis::{Factors, Running, mis, weight_connect, weight_direct, weight_to_camera};
use crate::{At, Bidir, Origin, SplatSink, Vertex};
use foton_core::api::{LightType, Ray, RayWalk, Reached, Rgb, Sampler, Scene, Vec3};

impl Bidir {
    /// t = 1 for a light vertex: connected to the pinhole and splatted on the pixels whose
    /// filter covers where it lands.
    pub fn splat_vertex(
        &self,
        scene: &Scene,
        v: &Vertex,
        sampler: &mut Sampler,
        splats: &mut impl SplatSink,
        rays: &mut u64,
    ) {
        let s = v.length + 1;
        if self.weight(s, 1, || 1.0) == 0.0 {
            return;
        }
        let camera = &scene.camera();
        let margin = scene.film().filter.margin();
        let Some(cs) = camera.sample_wi(v.p, margin, || sampler.next_2d()) else {
            return;
        };
        let f = v.f_light(cs.wi);
        if f == Rgb::ZERO {
            return;
        }
        let tr = if scene.render().hide_emitters {
            // Camera rays pass through emitters until they first scatter: so does this
            // connection, the camera subpath's first segment seen from its other end.
            Rgb::splat(seen_past_emitters(scene, v, cs.p, rays) as u8 as f32)
        } else {
            *rays += 1;
            let medium = v.medium_towards(scene, cs.wi);
            scene.transmittance(v.p, v.ng(), cs.p, Vec3::ZERO, medium)
        };
        if tr == Rgb::ZERO {
            return;
        }
        let base = v.beta * f * tr * (cs.we / cs.pdf);
        // The camera's density of having sampled v, per unit area there (filter aside).
        let pdf_camera = camera.pdf_area(&Ray::new(cs.p, -cs.wi), margin, v.cos(cs.wi), cs.dist);
        let pdf_rev = v.pdf(cs.wi, v.wo);
        let (width, height) = (scene.film().width, scene.film().height);
        scene
            .film()
            .filter
            .footprint(cs.film, width, height, |x, y, pdf, weight| {
                // The camera samples this point with density pdf; the pixel weights it by the
                // normalised filter pdf * weight (pdf itself for a positive filter).
                let w = self.weight(s, 1, || {
                    weight_to_camera(&self.factors, &v.running, pdf * pdf_camera, pdf_rev)
                });
                splats.add_strategy(s, x, y, base * (pdf * w), weight);
            });
    }

    /// s = 1, t = 1: a point of an area light connected to the pinhole (the light seen
    /// directly, as light tracing finds it).
    pub fn splat_origin(
        &self,
        scene: &Scene,
        o: &Origin,
        sampler: &mut Sampler,
        splats: &mut impl SplatSink,
        rays: &mut u64,
    ) {
        // With hide_emitters the camera does not see emitters directly (their s = 0, t = 2
        // twin never happens either: camera rays pass through them).
        if self.weight(1, 1, || 1.0) == 0.0 || scene.render().hide_emitters {
            return;
        }
        let camera = &scene.camera();
        let margin = scene.film().filter.margin();
        let Some(cs) = camera.sample_wi(o.p, margin, || sampler.next_2d()) else {
            return;
        };
        let light = &scene.lights()[o.light];
        let le = light.emitted(o.n, o.uv, cs.wi) * light.opacity(o.uv);
        if le == Rgb::ZERO {
            return;
        }
        *rays += 1;
        let tr = scene.transmittance(o.p, o.n, cs.p, Vec3::ZERO, o.medium);
        if tr == Rgb::ZERO {
            return;
        }
        let cos = o.n.dot(cs.wi).abs();
        let base = le * tr * (cos / o.pdf * cs.we / cs.pdf);
        let pdf_camera = camera.pdf_area(&Ray::new(cs.p, -cs.wi), margin, cos, cs.dist);
        // The only other strategy is the camera ray that reaches the point (s = 0, t = 2): no
        // merge builds this path (a light's origin is no stored vertex).
        let running = Running {
            d_vcm: mis(1.0 / o.pdf),
            d_vc: 0.0,
            d_vm: 0.0,
        };
        let (width, height) = (scene.film().width, scene.film().height);
        scene
            .film()
            .filter
            .footprint(cs.film, width, height, |x, y, pdf, weight| {
                let w = self.weight(1, 1, || {
                    weight_to_camera(&Factors::CONNECT, &running, pdf * pdf_camera, 0.0)
                });
                splats.add_strategy(1, x, y, base * (pdf * w), weight);
            });
    }

    /// s = 1: next-event estimation from camera vertex `c`.
    pub fn direct(&self, scene: &Scene, c: &Vertex, sampler: &mut Sampler, rays: &mut u64) -> Rgb {
        let u_light = sampler.next_f32();
        let (u, uc) = (sampler.next_2d(), sampler.next_f32());
        let t = c.length + 1;
        if self.weight(1, t, || 1.0) == 0.0 {
            return Rgb::ZERO;
        }
        let Some((id, pick)) = scene.sample_light(u_light) else {
            return Rgb::ZERO;
        };
        let light = &scene.lights()[id];
        let Some(ls) = light.sample_li(c.p, u, uc) else {
            return Rgb::ZERO;
        };
        if ls.li == Rgb::ZERO || ls.pdf.is_nan() || ls.pdf <= 0.0 {
            return Rgb::ZERO;
        }
        let f = c.f_camera(ls.wi);
        if f == Rgb::ZERO {
            return Rgb::ZERO;
        }
        *rays += 1;
        let medium = c.medium_towards(scene, ls.wi);
        let tr = scene.transmittance(c.p, c.ng(), ls.p, ls.n, medium);
        if tr == Rgb::ZERO {
            return Rgb::ZERO;
        }
        let direct_pdf = pick * ls.pdf;
        let w = self.weight(1, t, || {
            let (pos, pdf_dir) = light.pdf_le(ls.n, -ls.wi);
            let emission_pdf = pick * pos * pdf_dir;
            let cos_x = c.cos(ls.wi);
            // Emission's density of reaching c per unit area there, over next-event
            // estimation's of the light point per unit area on it (per solid angle for lights
            // at infinity; a point light's position is a discrete choice).
            let emission_ratio = match light.light_type() {
                LightType::Area => emission_pdf * cos_x / (direct_pdf * ls.n.dot(ls.wi).abs()),
                LightType::DeltaPosition => emission_pdf * cos_x / (pick * ls.dist * ls.dist),
                LightType::DeltaDirection | LightType::Infinite => {
                    emission_pdf * cos_x / direct_pdf
                }
                // A beam gives next-event estimation no sample to weigh.
                LightType::DeltaBeam => 0.0,
            };
            let hit_pdf = if ls.delta { 0.0 } else { c.pdf(c.wo, ls.wi) };
            weight_direct(
                &self.factors,
                &c.running,
                hit_pdf,
                direct_pdf,
                emission_ratio,
                c.pdf(ls.wi, c.wo),
            )
        });
        c.beta * f * ls.li * tr * (w / direct_pdf)
    }

    /// s, t >= 2: camera vertex `c` connected with light vertex `v`.
    pub fn connect(&self, scene: &Scene, c: &Vertex, v: &Vertex, rays: &mut u64) -> Rgb {
        let (s, t) = (v.length + 1, c.length + 1);
        if self.weight(s, t, || 1.0) == 0.0 {
            return Rgb::ZERO;
        }
        let d = v.p - c.p;
        let dist2 = d.length_squared();
        if dist2.is_nan() || dist2 <= 0.0 {
            return Rgb::ZERO;
        }
        let dir = d / dist2.sqrt();
        let f_c = c.f_camera(dir);
        if f_c == Rgb::ZERO {
            return Rgb::ZERO;
        }
        let f_v = v.f_light(-dir);
        if f_v == Rgb::ZERO {
            return Rgb::ZERO;
        }
        *rays += 1;
        let medium = c.medium_towards(scene, dir);
        let tr = scene.transmittance(c.p, c.ng(), v.p, v.ng(), medium);
        if tr == Rgb::ZERO {
            return Rgb::ZERO;
        }
        let w = self.weight(s, t, || {
            weight_connect(
                &self.factors,
                &c.running,
                &v.running,
                c.pdf(c.wo, dir) * v.cos(dir) / dist2,
                c.pdf(dir, c.wo),
                v.pdf(v.wo, -dir) * c.cos(dir) / dist2,
                v.pdf(-dir, v.wo),
            )
        });
        c.beta * f_c * f_v * v.beta * tr * (w / dist2)
    }
}

/// Whether light vertex `v` is seen from `origin` (the pinhole or a point of the lens) by a
/// camera ray that passes through emitters (`hide_emitters`, core's `RayWalk::camera`): what
/// it meets before `v` is all null boundaries or emitters, and `v` is not on an emitter itself (the camera sees through those).
/// Surfaces only: `hide_emitters` with media is refused.
fn seen_past_emitters(scene: &Scene, v: &Vertex, origin: Vec3, rays: &mut u64) -> bool {
    let At::Surface { hit: vh, .. } = &v.at else {
        return false;
    };
    if scene.object(vh).light.is_some() {
        return false;
    }
    let to = v.p - origin;
    let dist = to.length();
    let mut walk = RayWalk::camera(scene, Ray::new(origin, to / dist));
    loop {
        let seg = walk.segment(scene, rays);
        let Some(hit) = seg.hit else {
            return false;
        };
        match walk.reach(scene, &hit) {
            // The first surface that scatters must be v's: its primitive, near v (each
            // crossing offsets the ray a little off the line, which moves the hit at grazing
            // angles, so a tolerance of a few parts per thousand of the distance).
            Reached::Surface(_) => {
                return hit.prim == vh.prim
                    && std::ptr::eq(scene.object(&hit), scene.object(vh))
                    && hit.p.distance_squared(v.p) <= (5e-3 * dist).powi(2);
            }
            Reached::Ended => return false,
            Reached::Crossed => {}
        }
    }
}
