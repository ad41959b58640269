//! The MIS weights of bidirectional path tracing and of vertex connection and merging in O(1)
//! per connection or merge: the running quantities of Georgiev et al.'s implementation notes
//! ("Implementing vertex connection and merging", 2012; SmallVCM), `d_vcm`, `d_vc` and `d_vm`.
//! With merging switched off ([`Factors::CONNECT`]: both factors zero) the weights are exactly
//! Veach's bidirectional ones and `d_vm` is not used.
//!
//! Every subpath vertex carries two numbers from which the sum over all strategies that would
//! have sampled more of its subpath's vertices from the other side is one multiply-add away;
//! they are updated at each vertex from the pdfs of the direction sampled there (forward) and
//! of the reverse direction. Densities are per unit area at the vertices they land on (the
//! cosines are geometric normals'), per solid angle for lights at infinity. The power heuristic
//! (beta = 2) is a square of pdf ratios, so the quantities are kept squared ([`mis`]).
//!
//! A strategy's weight is 1 / (1 + w_light + w_camera), w_light summing the (squared) ratios of
//! the strategies with fewer light vertices, w_camera of those with fewer camera vertices.
//! Russian roulette is left out of the densities (as pbrt-v4 does): the weights of the
//! strategies of a path still sum to one, which is what unbiasedness needs.
//!
//! **Merging** (tech. rep. section 4): a merge of a light vertex with a camera vertex within
//! radius r is counted as a strategy whose density is the connection's times the acceptance
//! probability pi r^2 p(x) (p the density of the light vertex at the camera vertex's
//! position), with n_VM = N light paths per iteration against n_VC = 1 light path per
//! connection: eta_VCM = pi r^2 N. A connection's weight gains eta_VCM^2 for the merge that
//! would have built the same path ([`Factors::vm`]), a merge's counts each connection with
//! 1 / eta_VCM^2 ([`Factors::vc`]). `d_vm` accumulates, as `d_vc` does for connections, the
//! merges at earlier vertices.

/// The power heuristic's exponent applied to a pdf ratio.
#[inline]
pub fn mis(x: f32) -> f32 {
    x * x
}

/// The running quantities of one subpath vertex (squared, see the module comment).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Running {
    pub d_vcm: f32,
    pub d_vc: f32,
    /// The merges at earlier vertices (0 without merging).
    pub d_vm: f32,
}

/// The merging terms of the weights (SmallVCM's `mMisVmWeightFactor`, `mMisVcWeightFactor`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Factors {
    /// mis(eta_VCM) when merges are used, else 0: what a connection counts a merge as.
    pub vm: f32,
    /// mis(1 / eta_VCM) when connections are used, else 0: what a merge counts a connection
    /// (and the vertex's own d_vcm share) as.
    pub vc: f32,
}

impl Factors {
    /// Connections only (`bdpt`, `vcm`'s `bpt` mode).
    pub const CONNECT: Factors = Factors { vm: 0.0, vc: 0.0 };

    /// One iteration of `vcm` with merge radius `radius` and `light_paths` light subpaths:
    /// eta_VCM = pi r^2 N (tech. rep. eq. 20, with n_VC = 1 and n_VM = N).
    pub fn vcm(radius: f32, light_paths: f32, connect: bool, merge: bool) -> Factors {
        let eta = std::f32::consts::PI * radius * radius * light_paths;
        Factors {
            vm: if merge { mis(eta) } else { 0.0 },
            vc: if connect { mis(1.0 / eta) } else { 0.0 },
        }
    }
}

impl Running {
    /// A camera subpath's first vertex, the pinhole: `pdf_camera` is the density of the camera
    /// ray's direction in the pixel's estimate relative to one light path per camera sample:
    /// the pixel filter's density at the film point times the camera's `pdf_we` direction
    /// density (both per whole image: see `foton_core::camera`).
    pub fn camera(pdf_camera: f32) -> Running {
        Running {
            d_vcm: mis(1.0 / pdf_camera),
            d_vc: 0.0,
            d_vm: 0.0,
        }
    }

    /// A light subpath's first vertex, on the light: `emission_pdf` = pick x pdf_pos x pdf_dir
    /// of the emitted ray, `cos_light` the cosine there (1 for point lights and lights at
    /// infinity), `delta` for lights no path can hit (point, spot, directional). `d_vcm` is set
    /// at the first hit ([`Running::first_hit`]): next-event estimation's density of the origin
    /// depends on the point it is seen from.
    /// `factors.vc` starts `d_vm`: merging at the first vertex a light path reaches stands for
    /// the light's own emission, which only the connection strategies sample otherwise.
    pub fn light(emission_pdf: f32, cos_light: f32, delta: bool, factors: &Factors) -> Running {
        let d_vc = if delta {
            0.0
        } else {
            mis(cos_light / emission_pdf)
        };
        Running {
            d_vcm: 0.0,
            d_vc,
            d_vm: d_vc * factors.vc,
        }
    }

    /// At the first vertex a light path reaches: `direct_pdf` is the density with which
    /// next-event estimation from this vertex picks the light's origin (pick x pdf per unit
    /// area, per solid angle for lights at infinity; pick alone for point lights).
    pub fn first_hit(&mut self, direct_pdf: f32, emission_pdf: f32) {
        self.d_vcm = mis(direct_pdf / emission_pdf);
    }

    /// The subpath reaches a vertex at squared distance `dist2` from the last one (None: the
    /// first segment of a light at infinity, whose densities have no distance), where the
    /// cosine of the arriving direction with the geometric normal is `cos`.
    pub fn arrive(&mut self, dist2: Option<f32>, cos: f32) {
        if let Some(d2) = dist2 {
            self.d_vcm *= mis(d2);
        }
        let c = mis(cos.abs());
        self.d_vcm /= c;
        self.d_vc /= c;
        self.d_vm /= c;
    }

    /// The subpath scatters at this vertex: `cos_out` the cosine of the sampled direction with
    /// the geometric normal, `pdf_dir` its solid-angle density, `pdf_rev` the density of the
    /// reverse (the direction back, given the sampled one); a `delta` sample has equal
    /// forward and reverse probabilities, which cancel.
    /// (tech. rep. eqs. 34-36; the factors' terms are zero without merging).
    pub fn scatter(
        &mut self,
        cos_out: f32,
        pdf_dir: f32,
        pdf_rev: f32,
        delta: bool,
        factors: &Factors,
    ) {
        if delta {
            self.d_vcm = 0.0;
            self.d_vc *= mis(cos_out.abs());
            self.d_vm *= mis(cos_out.abs());
        } else {
            let g = mis(cos_out.abs() / pdf_dir);
            self.d_vc = g * (self.d_vc * mis(pdf_rev) + self.d_vcm + factors.vm);
            self.d_vm = g * (self.d_vm * mis(pdf_rev) + self.d_vcm * factors.vc + 1.0);
            self.d_vcm = mis(1.0 / pdf_dir);
        }
    }
}

/// The weight of a camera subpath that reaches an emitter (s = 0): `direct_pdf` the density of
/// next-event estimation picking that point from the previous vertex (per unit area; 0 when
/// that vertex could not connect), `emission_pdf` the light's pick x pdf_pos x pdf_dir of
/// emitting back along the path.
pub fn weight_emitter_hit(camera: &Running, direct_pdf: f32, emission_pdf: f32) -> f32 {
    let w_camera = mis(direct_pdf) * camera.d_vcm + mis(emission_pdf) * camera.d_vc;
    1.0 / (1.0 + w_camera)
}

/// The weight of next-event estimation (s = 1) from a camera vertex: `scatter_pdf` the
/// solid-angle density of the camera vertex sampling the direction to the light (0 for a light
/// no path can hit), `direct_pdf` next-event estimation's solid-angle density (pick included),
/// `emission_ratio` the light's density of emitting towards the vertex per unit area there over
/// next-event estimation's per unit area on the light, `pdf_rev` the camera vertex's density of
/// sampling back towards the camera given the light direction.
pub fn weight_direct(
    factors: &Factors,
    camera: &Running,
    scatter_pdf: f32,
    direct_pdf: f32,
    emission_ratio: f32,
    pdf_rev: f32,
) -> f32 {
    let w_light = mis(scatter_pdf / direct_pdf);
    let w_camera = mis(emission_ratio) * (factors.vm + camera.d_vcm + camera.d_vc * mis(pdf_rev));
    1.0 / (w_light + 1.0 + w_camera)
}

/// The weight of connecting a camera vertex with a light vertex (s, t >= 2). `*_dir_pdf` is each
/// vertex's density (per unit area at the other vertex) of having sampled the other; `*_rev_pdf`
/// its solid-angle density of sampling back along its own subpath, given the connection.
pub fn weight_connect(
    factors: &Factors,
    camera: &Running,
    light: &Running,
    camera_dir_pdf: f32,
    camera_rev_pdf: f32,
    light_dir_pdf: f32,
    light_rev_pdf: f32,
) -> f32 {
    let w_light =
        mis(camera_dir_pdf) * (factors.vm + light.d_vcm + light.d_vc * mis(light_rev_pdf));
    let w_camera =
        mis(light_dir_pdf) * (factors.vm + camera.d_vcm + camera.d_vc * mis(camera_rev_pdf));
    1.0 / (w_light + 1.0 + w_camera)
}

/// The weight of connecting a light vertex to the camera (t = 1): `camera_pdf` the camera's
/// density (filter x `pdf_we`, per unit area at the vertex) of having sampled it,
/// `light_rev_pdf` the vertex's solid-angle density of sampling back along its subpath.
pub fn weight_to_camera(
    factors: &Factors,
    light: &Running,
    camera_pdf: f32,
    light_rev_pdf: f32,
) -> f32 {
    let w_light = mis(camera_pdf) * (factors.vm + light.d_vcm + light.d_vc * mis(light_rev_pdf));
    1.0 / (w_light + 1.0)
}

/// The weight of merging a light vertex with a camera vertex (tech. rep. eqs. 37-39):
/// `camera_dir_pdf` the camera vertex's solid-angle density of sampling the light vertex's
/// incoming direction (the connection that would have continued the camera subpath),
/// `camera_rev_pdf` its density of sampling back along the camera subpath given that direction.
/// The merged path's light vertex stands in for the camera vertex, so the light side counts
/// the camera vertex's density through the light vertex's `d_vm`.
pub fn weight_merge(
    factors: &Factors,
    camera: &Running,
    light: &Running,
    camera_dir_pdf: f32,
    camera_rev_pdf: f32,
) -> f32 {
    let w_light = light.d_vcm * factors.vc + light.d_vm * mis(camera_dir_pdf);
    let w_camera = camera.d_vcm * factors.vc + camera.d_vm * mis(camera_rev_pdf);
    1.0 / (w_light + 1.0 + w_camera)
}

#[cfg(test)]
mod tests {
    use super::*;
    use foton_core::api::Camera;
    use foton_core::api::Rng;
    use foton_core::api::{Vec2, Vec3};
    use std::f32::consts::FRAC_1_PI;

    /// A diffuse vertex's solid-angle density of sampling `w` (two-sided, cosine-weighted).
    fn diffuse_pdf(n: Vec3, w: Vec3) -> f32 {
        n.dot(w).abs() * FRAC_1_PI
    }

    /// The weights of every strategy (s, t), s + t = k + 1, of random paths x0 (a pinhole) x1
    /// ... x_{k-1} (diffuse points) x_k (a point of an area light of area A, sampled uniformly
    /// by next-event estimation and emission, cosine-weighted directions), computed as the
    /// integrator computes them (the running quantities of both subpaths, then the weight of
    /// the connection), sum to one; and each strategy's weight is its power-heuristic share
    /// computed by brute force from the full path densities.
    #[test]
    fn the_weights_of_all_strategies_of_a_path_sum_to_one() {
        check_weights(None);
    }

    /// The same with merging (`vcm`): the connections and the merges at every vertex x_1 ...
    /// x_{k-1} (a camera subpath x0..x_i merged with a light subpath x_k..x_i, of density the
    /// connection's times eta_VCM p_light(x_i), tech. rep. section 4) of every path share one,
    /// each its power-heuristic share, for merges of little and of much weight.
    #[test]
    fn the_weights_of_all_connections_and_merges_of_a_path_sum_to_one() {
        for eta in [0.05f32, 1.3, 40.0] {
            check_weights(Some(eta));
        }
    }

    /// `eta`: eta_VCM = pi r^2 N of the merges (None: connections only).
    fn check_weights(eta: Option<f32>) {
        let f = eta.map_or(Factors::CONNECT, |e| Factors {
            vm: mis(e),
            vc: mis(1.0 / e),
        });
        let camera = Camera::new(
            Vec3::new(0.0, 1.0, 4.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::Y,
            40.0,
            64,
            48,
        );
        let area = 0.3f32;
        let pick = 0.7f32;
        let mut rng = Rng::new(&[19]);
        for k in 1..=6usize {
            for _ in 0..200 {
                // The path's vertices with their normals (x0, the pinhole, has none).
                let mut xs = vec![camera.position];
                let mut ns = vec![Vec3::ZERO];
                let film = Vec2::new(rng.next_f32() * 64.0, rng.next_f32() * 48.0);
                let first = camera.generate_ray(film);
                xs.push(first.at(1.0 + 3.0 * rng.next_f32()));
                for _ in 1..k {
                    let p = Vec3::new(
                        rng.next_f32() * 2.0 - 1.0,
                        rng.next_f32() * 2.0,
                        rng.next_f32() * 2.0 - 1.0,
                    );
                    xs.push(p);
                }
                for _ in 1..=k {
                    ns.push(foton_core::api::uniform_sphere(rng.next_2d()));
                }
                // The light's normal faces the vertex before it (it emits on that side).
                let to_prev = (xs[k - 1] - xs[k]).normalize();
                if ns[k].dot(to_prev) < 0.0 {
                    ns[k] = -ns[k];
                }
                let filter_pdf = 1.0f32;
                let dir = |a: usize, b: usize| (xs[b] - xs[a]).normalize();
                let d2 = |a: usize, b: usize| xs[a].distance_squared(xs[b]);
                let cos = |i: usize, w: Vec3| ns[i].dot(w).abs();
                let (_, pdf_we) = camera.pdf_we(&foton_core::api::Ray::new(xs[0], dir(0, 1)), 0.0);
                // Densities per unit area of each vertex sampled from the camera side (fwd)
                // and from the light side (rev), as Veach writes them.
                let mut fwd = vec![0.0f32; k + 1];
                let mut rev = vec![0.0f32; k + 1];
                fwd[1] = filter_pdf * pdf_we * cos(1, dir(1, 0)) / d2(0, 1);
                for i in 2..=k {
                    fwd[i] = diffuse_pdf(ns[i - 1], dir(i - 1, i)) * cos(i, dir(i, i - 1))
                        / d2(i - 1, i);
                }
                // From the light: x_k by emission (pick / A), x_{k-1} by its cosine direction,
                // then diffuse.
                rev[k] = pick / area;
                if k >= 1 {
                    rev[k - 1] = diffuse_pdf(ns[k], dir(k, k - 1)) * cos(k - 1, dir(k - 1, k))
                        / d2(k, k - 1);
                }
                for i in (1..k.saturating_sub(1)).rev() {
                    rev[i] = diffuse_pdf(ns[i + 1], dir(i + 1, i)) * cos(i, dir(i, i + 1))
                        / d2(i + 1, i);
                }
                // Next-event estimation picks x_k from x_{k-1} with pick / A too (uniform by
                // area), so the strategy s = 1 has the same density for x_k.
                // Strategy s's density: camera vertices x1..x_{t-1} forward, light vertices
                // x_{t}..x_k backwards (t = k + 1 - s).
                let density = |s: usize| -> f64 {
                    let t = k + 1 - s;
                    let camera: f64 = fwd[1..t].iter().map(|&p| p as f64).product();
                    let light: f64 = rev[t..=k].iter().map(|&p| p as f64).product();
                    camera * light
                };
                // The merge at x_i (1 <= i < k): x_i sampled from both sides, counted eta times.
                let merge = |i: usize| density(k - i) * rev[i] as f64 * eta.unwrap_or(0.0) as f64;
                let total: f64 = (0..=k).map(|s| density(s).powi(2)).sum::<f64>()
                    + (1..k).map(|i| merge(i).powi(2)).sum::<f64>();

                // A diffuse bounce at x_i from wo to wi.
                let diffuse_scatter = |r: &mut Running, i: usize, wo: Vec3, wi: Vec3| {
                    r.scatter(
                        cos(i, wi),
                        diffuse_pdf(ns[i], wi),
                        diffuse_pdf(ns[i], wo),
                        false,
                        &f,
                    )
                };
                // The running quantities along the camera subpath (x1 .. x_{k-1}).
                let mut cam = vec![Running::default(); k + 1];
                let mut r = Running::camera(filter_pdf * pdf_we);
                for (i, at) in cam.iter_mut().enumerate().skip(1) {
                    r.arrive(Some(d2(i - 1, i)), cos(i, dir(i, i - 1)));
                    *at = r;
                    if i < k {
                        let (wo, wi) = (dir(i, i - 1), dir(i, i + 1));
                        diffuse_scatter(&mut r, i, wo, wi);
                    }
                }
                // Along the light subpath (x_k, x_{k-1}, ..., x1).
                let mut lig = vec![Running::default(); k + 1];
                let cos_light = cos(k, dir(k, k - 1));
                let emission = pick / area * diffuse_pdf(ns[k], dir(k, k - 1));
                let mut r = Running::light(emission, cos_light, false, &f);
                lig[k] = Running {
                    d_vcm: mis(area / pick),
                    d_vc: 0.0,
                    d_vm: 0.0,
                };
                for i in (1..k).rev() {
                    if i == k - 1 {
                        r.first_hit(pick / area, emission);
                    }
                    r.arrive(Some(d2(i + 1, i)), cos(i, dir(i, i + 1)));
                    lig[i] = r;
                    if i > 1 {
                        let (wo, wi) = (dir(i, i + 1), dir(i, i - 1));
                        diffuse_scatter(&mut r, i, wo, wi);
                    }
                }

                let mut sum = 0.0f64;
                for s in 0..=k {
                    let t = k + 1 - s;
                    let w = if s == 0 {
                        // The camera subpath reaches x_k on the light.
                        // Next-event estimation (k > 1) and emission (k = 1, s = 1, t = 1) both
                        // pick the light point uniformly by area.
                        let direct = pick / area;
                        let emission = pick / area * diffuse_pdf(ns[k], dir(k, k - 1));
                        weight_emitter_hit(&cam[k], direct, emission)
                    } else if t == 1 {
                        // x_{s-1}... the light vertex x1 connected to the camera.
                        let camera_pdf = filter_pdf * pdf_we * cos(1, dir(1, 0)) / d2(0, 1);
                        let rev_pdf = if k == 1 {
                            0.0
                        } else {
                            diffuse_pdf(ns[1], dir(1, 2))
                        };
                        // The light's own point seen by the camera (k = 1) is no stored vertex: no
                        // merge builds that path (the integrator's `splat_origin`).
                        let f = if k == 1 { Factors::CONNECT } else { f };
                        weight_to_camera(&f, &lig[1], camera_pdf, rev_pdf)
                    } else if s == 1 {
                        // Next-event estimation from x_{k-1} to x_k.
                        let c = k - 1;
                        let wi = dir(c, k);
                        let scatter_pdf = diffuse_pdf(ns[c], wi);
                        let direct_w = pick / area * d2(c, k) / cos(k, wi);
                        let emission = pick / area * diffuse_pdf(ns[k], -wi);
                        let ratio = emission * cos(c, wi) / (direct_w * cos(k, wi));
                        weight_direct(
                            &f,
                            &cam[c],
                            scatter_pdf,
                            direct_w,
                            ratio,
                            diffuse_pdf(ns[c], dir(c, c - 1)),
                        )
                    } else {
                        // Camera vertex x_{t-1} connected with light vertex x_t.
                        let (c, l) = (t - 1, t);
                        let d = dir(c, l);
                        let dd = d2(c, l);
                        weight_connect(
                            &f,
                            &cam[c],
                            &lig[l],
                            diffuse_pdf(ns[c], d) * cos(l, d) / dd,
                            diffuse_pdf(ns[c], dir(c, c - 1)),
                            diffuse_pdf(ns[l], -d) * cos(c, d) / dd,
                            diffuse_pdf(ns[l], dir(l, l + 1)),
                        )
                    };
                    let want = density(s).powi(2) / total;
                    assert!(
                        (w as f64 - want).abs() < 2e-3 * want.max(1e-3),
                        "eta {eta:?}, k = {k}, (s, t) = ({s}, {t}): weight {w} vs power heuristic {want}"
                    );
                    sum += w as f64;
                }
                for i in (1..k).filter(|_| eta.is_some()) {
                    let w = weight_merge(
                        &f,
                        &cam[i],
                        &lig[i],
                        diffuse_pdf(ns[i], dir(i, i + 1)),
                        diffuse_pdf(ns[i], dir(i, i - 1)),
                    );
                    let want = merge(i).powi(2) / total;
                    assert!(
                        (w as f64 - want).abs() < 2e-3 * want.max(1e-3),
                        "eta {eta:?}, k = {k}, merge at x_{i}: weight {w} vs power heuristic {want}"
                    );
                    sum += w as f64;
                }
                assert!(
                    (sum - 1.0).abs() < 2e-3,
                    "eta {eta:?}, k = {k}: the weights sum to {sum}"
                );
            }
        }
    }
}
