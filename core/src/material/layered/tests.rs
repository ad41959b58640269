//! The layered lobes' tests: sampling against an exact density where one is known (a smooth
//! coat over a white Lambertian base), sample weights against eval cell by cell elsewhere,
//! energy (at most 1; exactly 1 for a lossless layer), reciprocity of the estimated f, and
//! the pdf's determinism and support.
//!
//! pbrt's pdf (`Layered::pdf`) is not the density with which `sample` draws directions: it
//! is an estimate of its main terms mixed with the uniform density, for multiple importance
//! sampling. So the sampling is checked against the exact density of the walk in the one
//! case where it has a closed form, and otherwise through its weights: in every cell of
//! directions, the mean of weight x [wi in cell] over samples must equal the integral of
//! eval over the cell (a z-test per cell), which holds only if directions and weights agree.

use super::*;
use crate::microfacet::chi2::{self, Outcome};
use crate::sampling::Rng;
use std::f64::consts::PI as PI64;

fn views() -> [Vec3; 3] {
    [
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(0.5, -0.4, 0.75).normalize(),
        Vec3::new(-0.8, 0.55, 0.2).normalize(),
    ]
}

fn coated_diffuse(roughness: f32, eta: f32, reflectance: f32, albedo: f32) -> Layered<Diffuse> {
    Layered {
        top: Dielectric {
            ggx: Ggx::new(roughness, roughness, true),
            eta,
        },
        base: Diffuse {
            reflectance: Rgb::splat(reflectance),
        },
        thickness: 0.01,
        albedo: Rgb::splat(albedo),
        g: 0.0,
        max_depth: 10,
        n_samples: 1,
    }
}

fn coated_conductor(interface: f32, conductor: f32, albedo: f32) -> Layered<Conductor> {
    let (eta, k) = crate::material::conductor_ior("Au").unwrap();
    Layered {
        top: Dielectric {
            ggx: Ggx::new(interface, interface, true),
            eta: 1.5,
        },
        base: Conductor {
            ggx: Ggx::new(conductor, conductor, true),
            eta: eta / 1.5,
            k: k / 1.5,
        },
        thickness: 0.01,
        albedo: Rgb::splat(albedo),
        g: 0.0,
        max_depth: 10,
        n_samples: 1,
    }
}

/// Either kind, for the tests that go over both.
#[derive(Clone, Copy, Debug)]
enum Case {
    Diffuse(Layered<Diffuse>),
    Conductor(Layered<Conductor>),
}

impl Case {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        match self {
            Case::Diffuse(l) => l.eval(wo, wi),
            Case::Conductor(l) => l.eval(wo, wi),
        }
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Case::Diffuse(l) => l.pdf(wo, wi),
            Case::Conductor(l) => l.pdf(wo, wi),
        }
    }
    fn sample(&self, wo: Vec3, u: Vec2, uc: f32) -> Option<LocalSample> {
        match self {
            Case::Diffuse(l) => l.sample(wo, u, uc, TransportMode::Radiance),
            Case::Conductor(l) => l.sample(wo, u, uc, TransportMode::Radiance),
        }
    }
}

/// Rough, scattering and mixed cases of both kinds (pbrt's default depth and sample count).
fn cases() -> Vec<Case> {
    let mut scattering = coated_diffuse(0.3, 1.5, 0.8, 0.8);
    scattering.thickness = 0.3;
    scattering.g = 0.5;
    let mut thick_conductor = coated_conductor(0.0, 0.2, 0.9);
    thick_conductor.thickness = 0.5;
    thick_conductor.g = -0.3;
    // Deep enough that no walk is cut short: at pbrt's 10 events `eval`, whose next-event
    // estimates reach one event further than `sample`'s walk, comes out 2% above it in this
    // thick scattering slab.
    thick_conductor.max_depth = 100;
    vec![
        Case::Diffuse(coated_diffuse(0.1, 1.5, 0.7, 0.0)),
        Case::Diffuse(coated_diffuse(0.5, 1.33, 0.5, 0.0)),
        Case::Diffuse(coated_diffuse(0.0, 1.5, 0.6, 0.0)),
        Case::Diffuse(scattering),
        Case::Conductor(coated_conductor(0.2, 0.1, 0.0)),
        Case::Conductor(coated_conductor(0.0, 0.3, 0.0)),
        Case::Conductor(coated_conductor(0.3, 0.0, 0.0)),
        Case::Conductor(thick_conductor),
    ]
}

/// Fresnel reflectance in f64 (for the exact density).
fn fresnel64(cos_i: f64, eta: f64) -> f64 {
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

/// The density of the directions `sample` draws for a smooth coat of index `eta` over a
/// white Lambertian base with a transparent slab and no depth limit: in through the coat
/// (probability 1 - R(wo); R is the delta reflection), a cosine-distributed direction at
/// the base after every bounce, out with probability 1 - F at each arrival under the coat,
/// else back to the base. Summed over the bounces, the inner exit direction has density
/// T_in(theta_t) cos_t / pi / (1 - r_i), r_i the coat's internal diffuse reflectance, and
/// outside p(wi) = (1 - R(wo)) (1 - F(cos_i)) cos_i / (pi eta^2 (1 - r_i)).
fn smooth_coat_density(eta: f64, wo: Vec3) -> impl Fn(Vec3) -> f64 {
    // r_i = 2 int_0^1 F_inner(mu) mu dmu (midpoint rule; F_inner is 1 beyond the critical
    // angle, a kink the fine grid resolves).
    let n = 200_000;
    let r_i: f64 = (0..n)
        .map(|j| {
            let mu = (j as f64 + 0.5) / n as f64;
            2.0 * fresnel64(mu, 1.0 / eta) * mu / n as f64
        })
        .sum();
    let enter = 1.0 - fresnel64(wo.z as f64, eta);
    move |wi: Vec3| {
        if wi.z <= 0.0 {
            return 0.0;
        }
        let cos_i = wi.z as f64;
        enter * (1.0 - fresnel64(cos_i, eta)) * cos_i / (PI64 * eta * eta * (1.0 - r_i))
    }
}

#[test]
fn smooth_coat_samples_follow_the_exact_density() {
    // Below eta 2: pbrt's Russian roulette of the walk starts where f / pdf falls under 1/4,
    // and inside the coat it is 1 / eta^2 (radiance), which would end walks early.
    let etas = [1.5f32, 1.33, 1.8];
    let tests = etas.len() * views().len();
    for (i, eta) in etas.into_iter().enumerate() {
        let mut lobe = coated_diffuse(0.0, eta, 1.0, 0.0);
        // No absorption in the slab, no depth limit: the walk ends only through the coat.
        lobe.thickness = f32::MIN_POSITIVE;
        lobe.max_depth = 100_000;
        for (j, wo) in views().into_iter().enumerate() {
            chi2::assert_fits(
                &format!("coated diffuse eta {eta}, wo {wo}"),
                100_000,
                (10 * i + j) as u64,
                |rng: &mut Rng| {
                    let u = rng.next_2d();
                    match lobe.sample(wo, u, rng.next_f32(), TransportMode::Radiance) {
                        Some(s) if !s.delta => Outcome::Dir(s.wi),
                        _ => Outcome::Other,
                    }
                },
                &smooth_coat_density(eta as f64, wo),
                chi2::sidak(tests),
            );
        }
    }
}

/// Cells of the upper hemisphere: uniform in cos(theta) and phi.
const CELLS_COS: usize = 6;
const CELLS_PHI: usize = 8;

fn cell_of(wi: Vec3) -> usize {
    let c = ((wi.z.clamp(0.0, 1.0) * CELLS_COS as f32) as usize).min(CELLS_COS - 1);
    let phi = wi.y.atan2(wi.x).rem_euclid(2.0 * PI);
    let p = ((phi / (2.0 * PI) * CELLS_PHI as f32) as usize).min(CELLS_PHI - 1);
    c * CELLS_PHI + p
}

/// Per cell, the mean and variance of a per-draw estimate (luminance-free: the channels'
/// mean) of the cell's integral.
struct Tally {
    sum: Vec<f64>,
    sum2: Vec<f64>,
    n: usize,
}

impl Tally {
    fn new(n: usize) -> Tally {
        Tally {
            sum: vec![0.0; CELLS_COS * CELLS_PHI],
            sum2: vec![0.0; CELLS_COS * CELLS_PHI],
            n,
        }
    }
    fn add(&mut self, cell: usize, x: f64) {
        self.sum[cell] += x;
        self.sum2[cell] += x * x;
    }
    fn mean(&self, cell: usize) -> f64 {
        self.sum[cell] / self.n as f64
    }
    fn variance_of_mean(&self, cell: usize) -> f64 {
        let m = self.mean(cell);
        (self.sum2[cell] / self.n as f64 - m * m).max(0.0) / self.n as f64
    }
}

/// The z-test of every cell: sample weights (non-delta) falling in it against eval integrated
/// over it by uniform points; returns the largest |z|, the totals of both sides (the
/// directional albedo without the delta part) and the standard deviation of their difference.
fn weights_against_eval(case: Case, wo: Vec3, n: usize, seed: u64) -> (f64, f64, f64, f64) {
    let mut rng = Rng::new(&[seed]);
    let mut sampled = Tally::new(n);
    for _ in 0..n {
        let u = rng.next_2d();
        if let Some(s) = case.sample(wo, u, rng.next_f32())
            && !s.delta
        {
            assert!(
                s.wi.z > 0.0 && s.weight.is_finite() && s.pdf > 0.0,
                "{case:?} {s:?}"
            );
            sampled.add(cell_of(s.wi), crate::average(s.weight) as f64);
        }
    }
    // Uniform directions over the hemisphere (pdf 1 / 2 pi): eval / pdf lands in the cell.
    let mut evaluated = Tally::new(n);
    for _ in 0..n {
        let (u, v) = (rng.next_f32(), rng.next_f32());
        let z = u;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * PI * v;
        let wi = Vec3::new(r * phi.cos(), r * phi.sin(), z);
        if wi.z <= 0.0 {
            continue;
        }
        let e = crate::average(case.eval(wo, wi)) as f64;
        assert!(e.is_finite() && e >= 0.0, "{case:?} eval {e}");
        evaluated.add(cell_of(wi), e * 2.0 * PI64);
    }
    let (mut worst, mut total_s, mut total_e, mut total_var) = (0.0f64, 0.0, 0.0, 0.0);
    for c in 0..CELLS_COS * CELLS_PHI {
        let (a, b) = (sampled.mean(c), evaluated.mean(c));
        total_s += a;
        total_e += b;
        let var = sampled.variance_of_mean(c) + evaluated.variance_of_mean(c);
        total_var += var;
        let sd = var.sqrt();
        // Cells neither side reached are not tested; a cell one side reached and the other
        // never did fails through its tiny standard deviation.
        if sd > 0.0 {
            worst = worst.max((a - b).abs() / sd.max(1e-4 * (a + b)));
        }
    }
    (worst, total_s, total_e, total_var.sqrt())
}

#[test]
fn sample_weights_match_eval_cell_by_cell() {
    for (i, case) in cases().into_iter().enumerate() {
        for (j, wo) in views().into_iter().enumerate() {
            let (worst, s, e, sd) = weights_against_eval(case, wo, 200_000, (100 * i + j) as u64);
            // 48 cells x 24 tests: |z| below 4.5 has a family-wise false-alarm rate near
            // 1e-2 for normal errors; heavy-tailed weights get a little slack.
            assert!(
                worst < 5.0,
                "{case:?} wo {wo}: a cell differs by {worst:.2} sd (totals {s:.4} sampled, {e:.4} evaluated)"
            );
            assert!(
                (s - e).abs() < 4.0 * sd + 1e-3,
                "{case:?} wo {wo}: sampled {s:.4} vs evaluated {e:.4} (sd {sd:.4})"
            );
        }
    }
}

/// Directional albedo by the mean sample weight (delta reflection included), with its
/// standard error.
fn albedo(case: Case, wo: Vec3, n: usize, seed: u64) -> (f64, f64) {
    let mut rng = Rng::new(&[seed]);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let u = rng.next_2d();
        if let Some(s) = case.sample(wo, u, rng.next_f32()) {
            let w = s.weight.max_element() as f64;
            sum += w;
            sum2 += w * w;
        }
    }
    let mean = sum / n as f64;
    (
        mean,
        ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt(),
    )
}

#[test]
fn albedo_is_at_most_one() {
    let mut all = cases();
    for r in [0.0, 0.05, 0.3, 1.0] {
        for eta in [1.1, 1.5, 2.5] {
            let mut white = coated_diffuse(r, eta, 1.0, 1.0);
            white.g = 0.7;
            all.push(Case::Diffuse(white));
            all.push(Case::Diffuse(coated_diffuse(r, eta, 1.0, 0.0)));
        }
        let mut mirror = coated_conductor(r, r, 1.0);
        mirror.base.eta = Rgb::ZERO; // F = 1: a perfect mirror under the coat
        mirror.base.k = Rgb::ZERO;
        all.push(Case::Conductor(mirror));
    }
    for (i, case) in all.into_iter().enumerate() {
        for (j, wo) in views().into_iter().enumerate() {
            let (a, se) = albedo(case, wo, 20_000, (100 * i + j) as u64);
            assert!(
                a <= 1.0 + 4.0 * se + 1e-3,
                "{case:?} wo {wo}: albedo {a} +- {se}"
            );
        }
    }
}

#[test]
fn lossless_layers_reflect_everything() {
    // A white base under a smooth coat, the slab transparent (no thickness) or scattering
    // without absorption, and enough depth that no walk is cut short: all the light comes
    // back out (the furnace test of the layer).
    let mut clear = coated_diffuse(0.0, 1.5, 1.0, 0.0);
    clear.thickness = f32::MIN_POSITIVE;
    let mut milky = coated_diffuse(0.0, 1.5, 1.0, 1.0);
    milky.thickness = 0.5;
    milky.g = 0.4;
    for (i, mut lobe) in [clear, milky].into_iter().enumerate() {
        lobe.max_depth = 10_000;
        for (j, wo) in views().into_iter().enumerate() {
            let (a, se) = albedo(Case::Diffuse(lobe), wo, 40_000, (100 * i + j) as u64);
            assert!(
                (a - 1.0).abs() < 4.0 * se + 0.005,
                "{lobe:?} wo {wo}: albedo {a} +- {se}"
            );
        }
    }
    // A rough coat loses what its microfacets scatter below the horizon at each of the
    // light's arrivals under it (pbrt's single-scattering microfacet model), more the
    // rougher it is: measured, and bounded.
    let mut previous = 1.0;
    for (roughness, at_least) in [(0.001, 0.97), (0.01, 0.88), (0.1, 0.6), (0.3, 0.45)] {
        let mut lobe = coated_diffuse(roughness, 1.5, 1.0, 0.0);
        lobe.thickness = f32::MIN_POSITIVE;
        lobe.max_depth = 10_000;
        let (a, se) = albedo(Case::Diffuse(lobe), Vec3::Z, 40_000, 3);
        eprintln!("roughness {roughness}: albedo {a:.4} +- {se:.4}");
        assert!(
            a >= at_least && a <= previous + 4.0 * se,
            "roughness {roughness}: albedo {a}"
        );
        previous = a;
    }
    // pbrt's default depth, 10 events, loses what is still inside after 5 round trips.
    let mut clear = coated_diffuse(0.0, 1.5, 1.0, 0.0);
    clear.thickness = f32::MIN_POSITIVE;
    let (a, _) = albedo(Case::Diffuse(clear), Vec3::Z, 40_000, 7);
    assert!(a < 0.97 && a > 0.8, "albedo at depth 10: {a}");
}

#[test]
fn estimated_f_is_reciprocal() {
    // With many walks per evaluation the estimate is close to its expectation, which is
    // reciprocal: f(wo, wi) = f(wi, wo) (eval carries cos theta_i).
    let pairs = [
        (Vec3::new(0.3, 0.1, 0.95), Vec3::new(-0.6, 0.3, 0.74)),
        (Vec3::new(0.8, -0.2, 0.3), Vec3::new(0.1, 0.5, 0.7)),
    ];
    for case in cases() {
        let case = match case {
            Case::Diffuse(mut l) => {
                l.n_samples = 20_000;
                l.max_depth = 100;
                Case::Diffuse(l)
            }
            Case::Conductor(mut l) => {
                l.n_samples = 20_000;
                l.max_depth = 100;
                Case::Conductor(l)
            }
        };
        for (a, b) in pairs {
            let (a, b) = (a.normalize(), b.normalize());
            let f_ab = case.eval(a, b) / b.z;
            let f_ba = case.eval(b, a) / a.z;
            let scale = f_ab.max_element().max(f_ba.max_element());
            assert!(
                (f_ab - f_ba).abs().max_element() <= 0.05 * scale + 1e-3,
                "{case:?}: f({a}, {b}) = {f_ab} but f({b}, {a}) = {f_ba}"
            );
        }
    }
}

#[test]
fn pdf_is_deterministic_positive_where_eval_is_and_two_sided() {
    let mut rng = Rng::new(&[5]);
    for case in cases() {
        for wo in views() {
            for _ in 0..200 {
                let wi = crate::sampling::uniform_sphere(rng.next_2d());
                let (e, p) = (case.eval(wo, wi), case.pdf(wo, wi));
                assert_eq!(e, case.eval(wo, wi), "{case:?}: eval is not deterministic");
                assert_eq!(p, case.pdf(wo, wi), "{case:?}: pdf is not deterministic");
                if wi.z <= 0.0 {
                    assert_eq!((e, p), (Rgb::ZERO, 0.0), "{case:?}: light through the base");
                } else {
                    assert!(p > 0.0 && p.is_finite(), "{case:?}: pdf {p}");
                }
                // Seen from below, the mirror image.
                assert_eq!(case.eval(-wo, -wi), e);
                assert_eq!(case.pdf(-wo, -wi), p);
            }
        }
    }
}

#[test]
fn a_sample_gives_the_pdf_of_its_pair() {
    // Multiple importance sampling compares a sample's pdf with `pdf` of the same pair.
    let mut rng = Rng::new(&[11]);
    for case in cases() {
        for wo in views() {
            for _ in 0..200 {
                let u = rng.next_2d();
                if let Some(s) = case.sample(wo, u, rng.next_f32())
                    && !s.delta
                {
                    assert_eq!(s.pdf, case.pdf(wo, s.wi), "{case:?}");
                }
            }
        }
    }
}

#[test]
fn smooth_coat_reflects_its_fresnel_share_as_a_delta() {
    let lobe = coated_diffuse(0.0, 1.5, 0.5, 0.0);
    for wo in views() {
        let r = crate::scattering::fresnel_dielectric(wo.z, 1.5);
        assert_eq!(lobe.delta_probability(wo), r);
        // uc below R: the mirror direction, weight 1, pdf R.
        let s = lobe
            .sample(wo, Vec2::splat(0.5), 0.5 * r, TransportMode::Radiance)
            .unwrap();
        assert!(s.delta && (s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
        assert!((s.weight - Rgb::ONE).abs().max_element() < 1e-5 && s.pdf == r);
    }
    assert_eq!(
        coated_diffuse(0.2, 1.5, 0.5, 0.0).delta_probability(Vec3::Z),
        0.0
    );
    assert_eq!(
        coated_diffuse(0.2, 1.5, 0.5, 0.0).roughness(),
        0.2f32.sqrt()
    );
    assert_eq!(
        coated_diffuse(0.0, 1.5, 0.5, 0.0).roughness(),
        f32::INFINITY
    );
    // A smooth coat on a smooth metal with a clear slab: every path is a delta.
    let mirror = coated_conductor(0.0, 0.0, 0.0);
    assert_eq!(
        (mirror.roughness(), mirror.delta_probability(Vec3::Z)),
        (0.0, 1.0)
    );
    let s = mirror
        .sample(Vec3::Z, Vec2::splat(0.3), 0.9, TransportMode::Radiance)
        .unwrap();
    assert!(s.delta && s.wi.z > 0.99);
}

#[test]
fn odd_input_gives_zero_not_nan() {
    for case in cases() {
        for (wo, wi) in [
            (Vec3::new(1.0, 0.0, 0.0), Vec3::Z),
            (Vec3::Z, Vec3::new(0.0, 1.0, 0.0)),
            (Vec3::splat(f32::NAN), Vec3::Z),
            (Vec3::Z, Vec3::splat(f32::INFINITY)),
        ] {
            let (e, p) = (case.eval(wo, wi), case.pdf(wo, wi));
            assert!(
                e.is_finite() && p.is_finite(),
                "{case:?} {wo} {wi}: {e} {p}"
            );
        }
        assert!(
            case.sample(Vec3::splat(f32::NAN), Vec2::splat(0.5), 0.5)
                .is_none()
        );
    }
}

#[test]
fn interface_samples_agree_with_their_f_and_pdf() {
    // Each interface's sample carries f and pdf equal to `f` and `pdf` of its pair, and its
    // mean weight (f |cos| / pdf, delta parts included) is its albedo, at most 1.
    let dielectric = |r: f32, eta: f32| Dielectric {
        ggx: Ggx::new(r, r, true),
        eta,
    };
    let (au_eta, au_k) = crate::material::conductor_ior("Au").unwrap();
    let conductor = Conductor {
        ggx: Ggx::new(0.2, 0.05, true),
        eta: au_eta,
        k: au_k,
    };
    let check = |name: &str, i: &dyn Interface, wo: Vec3, flags: Flags| {
        let mut rng = Rng::new(&[3]);
        let n = 20_000;
        let mut albedo = 0.0f64;
        for _ in 0..n {
            let (uc, u) = (rng.next_f32(), rng.next_2d());
            let Some(s) = i.sample(wo, uc, u, TransportMode::Importance, flags) else {
                continue;
            };
            albedo += (crate::average(s.f) * s.wi.z.abs() / s.pdf) as f64 / n as f64;
            if s.specular {
                continue;
            }
            let f = i.f(wo, s.wi, TransportMode::Importance);
            assert!(
                (f - s.f).abs().max_element() <= 1e-2 * f.max_element().max(1e-3),
                "{name} wo {wo}: f {f} sampled {}",
                s.f
            );
            let p = i.pdf(wo, s.wi, flags);
            assert!(
                (p - s.pdf).abs() <= 1e-2 * p.max(1e-3),
                "{name} wo {wo}: pdf {p} sampled {}",
                s.pdf
            );
        }
        assert!(albedo <= 1.01, "{name} wo {wo}: albedo {albedo}");
        albedo
    };
    for wo in views().into_iter().chain([
        Vec3::new(0.3, 0.2, -0.9).normalize(),
        Vec3::new(0.2, -0.85, -0.5).normalize(),
    ]) {
        for r in [0.0f32, 0.1, 0.3] {
            let d = dielectric(r, 1.5);
            let all = check("dielectric", &d, wo, Flags::All);
            if r > 0.0 && wo.z > 0.5 {
                // Rough glass loses a little to the single-scattering microfacet model.
                assert!(all > 0.9, "dielectric {r} wo {wo}: albedo {all}");
            }
            check("dielectric, reflection", &d, wo, Flags::Reflection);
            check("dielectric, transmission", &d, wo, Flags::Transmission);
        }
        check("conductor", &conductor, wo, Flags::All);
        check(
            "diffuse",
            &Diffuse {
                reflectance: Rgb::ONE,
            },
            wo,
            Flags::All,
        );
    }
}
