//! The samplers (`[render] sampler`): `independent` is the old per-sample stream bit for bit;
//! `stratified` hits each stratum of every dimension exactly once per pixel; `sobol` gives
//! every pixel an Owen-scrambled (0, m, 2)-net in every dimension pair, however far down the
//! path (padding); all three are uniform over pixels (chi-square), pairs of dimensions are
//! independent of each other; the quasi-random photon emission points are nets too. Then the
//! images: `sobol` and `stratified` converge to the `independent` image (no bias) and `sobol`
//! has clearly less error at 16 spp on an area-lit scene.

use foton_core::sampling::independent::Independent;
use foton_core::sampling::sobol::Sobol;
use foton_core::sampling::stratified::Stratified;
use foton_core::sampling::{
    Rng, SAMPLERS, SOBOL_DIMENSIONS, Sampler, SamplerKind, SobolPoint, owen_scramble,
    shuffled_index, sobol_dimension, strata_2d,
};
use foton_tests::render_toml;
use foton_tests::stats::rel_rmse;
use glam::Vec2;

fn kinds() -> [SamplerKind; 4] {
    [
        SamplerKind::from(Independent),
        SamplerKind::from(Stratified { jitter: true }),
        SamplerKind::from(Stratified { jitter: false }),
        SamplerKind::from(Sobol),
    ]
}

/// The draws of one camera sample: 2-D, 1-D, 2-D, 1-D, ... (as a path asks for them).
fn draws(s: &mut Sampler, n: usize) -> Vec<Vec2> {
    (0..n)
        .map(|d| {
            if d % 2 == 0 {
                s.next_2d()
            } else {
                Vec2::new(s.next_f32(), -1.0)
            }
        })
        .collect()
}

/// All samples of one pixel: `[sample][draw]`.
fn pixel(kind: SamplerKind, seed: u64, px: u64, spp: u32, n: usize) -> Vec<Vec<Vec2>> {
    (0..spp)
        .map(|i| draws(&mut Sampler::new(kind, seed, px, i, spp), n))
        .collect()
}

#[test]
fn independent_is_the_old_stream_bit_for_bit() {
    for key in 0..200u64 {
        let (seed, px, i) = (key % 3, key * 7919, (key % 17) as u32);
        let mut old = Rng::new(&[seed, px, i as u64]);
        let mut new = Sampler::new(SamplerKind::from(Independent), seed, px, i, 16);
        for d in 0..40 {
            if d % 3 == 0 {
                assert_eq!(old.next_2d(), new.next_2d());
            } else {
                assert_eq!(old.next_f32().to_bits(), new.next_f32().to_bits());
            }
        }
    }
}

#[test]
fn stratified_hits_every_stratum_of_every_dimension_once_per_pixel() {
    for jitter in [true, false] {
        let kind = SamplerKind::from(Stratified { jitter });
        for spp in [1, 2, 7, 12, 16, 30] {
            let (nx, ny) = strata_2d(spp);
            assert_eq!(nx * ny, spp);
            for px in [0u64, 1, 99] {
                let samples = pixel(kind, 5, px, spp, 12);
                for d in 0..12 {
                    let mut hit = vec![0u32; spp as usize];
                    for s in &samples {
                        let u = s[d];
                        assert!((0.0..1.0).contains(&u.x), "{u}");
                        let cell = if d % 2 == 0 {
                            let (cx, cy) = ((u.x * nx as f32) as u32, (u.y * ny as f32) as u32);
                            if !jitter {
                                let centre = Vec2::new(
                                    (cx as f32 + 0.5) / nx as f32,
                                    (cy as f32 + 0.5) / ny as f32,
                                );
                                assert!((u - centre).abs().max_element() < 1e-6, "{u}");
                            }
                            cy * nx + cx
                        } else {
                            (u.x * spp as f32) as u32
                        };
                        hit[cell as usize] += 1;
                    }
                    assert!(
                        hit.iter().all(|&h| h == 1),
                        "spp {spp}, jitter {jitter}, pixel {px}, draw {d}: {hit:?}"
                    );
                }
            }
        }
    }
}

/// Each elementary interval 2^-a x 2^-(m-a) of the unit square holds exactly one of 2^m points.
fn is_02_net(points: &[Vec2], m: u32) -> bool {
    (0..=m).all(|a| {
        let (nx, ny) = (1u32 << a, 1u32 << (m - a));
        let mut hit = vec![0u32; 1 << m];
        for p in points {
            let (cx, cy) = ((p.x * nx as f32) as u32, (p.y * ny as f32) as u32);
            hit[(cy * nx + cx) as usize] += 1;
        }
        hit.iter().all(|&h| h == 1)
    })
}

#[test]
fn sobol_gives_every_pixel_a_net_in_every_dimension_pair_even_far_down_the_path() {
    let m = 6;
    for px in [0u64, 1, 12345] {
        // 200 draws: dimensions of a path a hundred bounces long are still padded pairs.
        let samples = pixel(SamplerKind::from(Sobol), 3, px, 1 << m, 200);
        for d in 0..200 {
            let points: Vec<Vec2> = samples.iter().map(|s| s[d]).collect();
            if d % 2 == 0 {
                assert!(is_02_net(&points, m), "pixel {px}, draw {d}");
            } else {
                let mut hit = vec![0u32; 1 << m];
                for p in &points {
                    hit[(p.x * (1 << m) as f32) as usize] += 1;
                }
                assert!(hit.iter().all(|&h| h == 1), "pixel {px}, draw {d}");
            }
        }
        // Neighbouring pixels do not share a pattern.
        let next = pixel(SamplerKind::from(Sobol), 3, px + 1, 1 << m, 2);
        assert!(samples[0][0] != next[0][0] && samples[1][1] != next[1][1]);
    }
}

/// Pearson's chi-square of counts against equal expectations.
fn chi_square(counts: &[u32]) -> f64 {
    let n: u32 = counts.iter().sum();
    let want = n as f64 / counts.len() as f64;
    counts
        .iter()
        .map(|&c| (c as f64 - want).powi(2) / want)
        .sum()
}

/// Over many pixels, each draw is uniform (64 bins), and two draws taken together are uniform
/// on the square (8 x 8 bins): no correlation between dimensions, early or late in the path.
/// The bound is the chi-square with 63 degrees of freedom at p = 1e-6 (about 131).
#[test]
fn every_sampler_is_uniform_per_dimension_and_per_pair_over_pixels() {
    const BOUND: f64 = 131.0;
    // Centred strata are a lattice by design (16 values per draw), not uniform in 64 bins.
    for kind in kinds()
        .into_iter()
        .filter(|k| *k != SamplerKind::from(Stratified { jitter: false }))
    {
        let spp = 16;
        let pixels: Vec<Vec<Vec<Vec2>>> =
            (0..400u64).map(|px| pixel(kind, 9, px, spp, 64)).collect();
        for (a, b) in [(0, 1), (1, 2), (2, 3), (5, 6), (60, 61), (62, 63), (0, 63)] {
            let mut one = vec![0u32; 64];
            let mut two = vec![0u32; 64];
            for s in pixels.iter().flatten() {
                let (u, v) = (s[a].x, s[b].x);
                one[(u * 64.0) as usize] += 1;
                two[(v * 8.0) as usize * 8 + (u * 8.0) as usize] += 1;
            }
            let (c1, c2) = (chi_square(&one), chi_square(&two));
            assert!(c1 < BOUND, "{kind:?}, draw {a}: chi-square {c1:.1}");
            assert!(c2 < BOUND, "{kind:?}, draws {a} x {b}: chi-square {c2:.1}");
        }
        // The two coordinates of each 2-D draw (the film position, a late bounce).
        for d in [0, 2, 62] {
            let mut two = vec![0u32; 64];
            for s in pixels.iter().flatten() {
                two[(s[d].y * 8.0) as usize * 8 + (s[d].x * 8.0) as usize] += 1;
            }
            let c = chi_square(&two);
            assert!(c < BOUND, "{kind:?}, 2-D draw {d}: chi-square {c:.1}");
        }
    }
}

#[test]
fn stratified_with_more_samples_than_strata_starts_new_permutations() {
    // sppm's iterations without a bound: index past spp, each round still one per stratum.
    let kind = SamplerKind::from(Stratified { jitter: true });
    let mut hit = [[0u32; 4]; 3];
    for i in 0..12 {
        let u = Sampler::new(kind, 1, 7, i, 4).next_f32();
        hit[(i / 4) as usize][(u * 4.0) as usize] += 1;
    }
    assert_eq!(hit, [[1; 4]; 3]);
}

/// The photon emission points: Owen-scrambled Sobol in six dimensions sharing one index
/// shuffle. Every dimension is a (0, m, 1)-net, the first pair a (0, m, 2)-net, and every
/// pair of the six a (t, m, 2)-net with a small t (an error in a generator matrix shows as a
/// large t); different seeds give different points.
#[test]
fn photon_emission_points_are_nets_in_every_pair_of_dimensions() {
    let m = 10;
    for seed in [0u64, 77] {
        let points: Vec<[f32; SOBOL_DIMENSIONS]> = (0..1u64 << m)
            .map(|i| {
                let mut p = SobolPoint::new(i, seed);
                std::array::from_fn(|_| p.next_f32().unwrap())
            })
            .collect();
        for a in 0..SOBOL_DIMENSIONS {
            for b in a + 1..SOBOL_DIMENSIONS {
                let pair: Vec<Vec2> = points.iter().map(|p| Vec2::new(p[a], p[b])).collect();
                let t = (0..=m).find(|&t| t_net(&pair, m, t)).unwrap();
                let most = if (a, b) == (0, 1) { 0 } else { 3 };
                assert!(t <= most, "seed {seed}, dimensions {a}, {b}: t = {t}");
            }
        }
    }
    let mut p = SobolPoint::new(5, 1);
    let mut q = SobolPoint::new(5, 2);
    assert_ne!(p.next_f32(), q.next_f32());
}

/// Every elementary interval of volume 2^(t - m) holds exactly 2^t of the 2^m points.
fn t_net(points: &[Vec2], m: u32, t: u32) -> bool {
    (0..=m - t).all(|a| {
        let (nx, ny) = (1u32 << a, 1u32 << (m - t - a));
        let mut hit = vec![0u32; 1 << (m - t)];
        for p in points {
            let (cx, cy) = ((p.x * nx as f32) as u32, (p.y * ny as f32) as u32);
            hit[(cy * nx + cx) as usize] += 1;
        }
        hit.iter().all(|&h| h == 1 << t)
    })
}

#[test]
fn sobol_matrices_are_those_of_the_sobol_sequence() {
    // The first points of Joe and Kuo's sequence in index order (not Gray-code order).
    let at = |i, d| sobol_dimension(i, d) as f64 / 2f64.powi(32);
    assert_eq!((at(1, 0), at(2, 0), at(3, 0)), (0.5, 0.25, 0.75));
    assert_eq!((at(1, 1), at(2, 1), at(3, 1)), (0.5, 0.75, 0.25));
    assert_eq!((at(1, 2), at(2, 2), at(3, 2)), (0.5, 0.75, 0.25));
    // Past the initial numbers, by the recurrence: m_3 = 3 in dimension 2, m_4 = 5 in 3.
    assert_eq!((at(4, 2), at(4, 3), at(4, 4)), (0.375, 0.125, 0.125));
    assert_eq!(at(8, 3), 0.3125);
    // Owen scrambling permutes: the 2^8 first points stay a 1-D net under any seed.
    let mut seen = vec![false; 256];
    for i in 0..256u32 {
        seen[(owen_scramble(i << 24, 0xDEAD_BEEF) >> 24) as usize] = true;
    }
    assert!(seen.iter().all(|&s| s));
    // The index shuffle permutes the first 2^k indices among themselves for every k.
    for seed in [1u32, 0xFFFF_FFFF, 12345] {
        for k in 0..12 {
            let mut seen = vec![false; 1 << k];
            for i in 0..1u32 << k {
                seen[shuffled_index(i, seed) as usize] = true;
            }
            assert!(seen.iter().all(|&s| s), "seed {seed}, 2^{k}");
        }
    }
}

/// A small diffuse box lit by an area light on its ceiling, direct light only: soft shadows of
/// a floating square, where well-distributed points help most.
fn area_lit(spp: u32) -> String {
    format!(
        r#"
[render]
integrator = "path"
spp = {spp}
seed = 3
max_depth = 1

[film]
width = 16
height = 16
output = "out.exr"

[camera]
position = [0.0, 2.5, 2.5]
look_at = [0.0, 0.0, 0.0]
fov = 50.0

[materials.white]
type = "diffuse"
reflectance = [0.7, 0.7, 0.7]

[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

# The floor, normal up.
[[shapes]]
type = "quad"
material = "white"
origin = [-1.5, 0.0, 1.5]
u = [3.0, 0.0, 0.0]
v = [0.0, 0.0, -3.0]

# A floating square between light and floor: a penumbra across much of the image.
[[shapes]]
type = "quad"
material = "white"
origin = [-0.4, 0.6, 0.4]
u = [0.8, 0.0, 0.0]
v = [0.0, 0.0, -0.8]

# The light, facing down.
[[shapes]]
type = "quad"
material = "black"
origin = [-0.5, 1.5, -0.5]
u = [1.0, 0.0, 0.0]
v = [0.0, 0.0, 1.0]
emission = [5.0, 5.0, 5.0]
"#
    )
}

fn render_area_lit(sampler: &str, spp: u32, seed: u64) -> foton_core::film::Film {
    render_toml(
        &format!("samplers-{sampler}-{spp}-{seed}"),
        &area_lit(spp),
        &[
            &format!("render.sampler={sampler:?}"),
            &format!("render.seed={seed}"),
        ],
        2,
    )
}

/// Against a reference the test makes (independent, 4096 spp): at 16 spp, `sobol`'s RMSE is
/// under 0.8x `independent`'s and `stratified`'s under 0.9x (each over 4 seeds); and at 256 spp
/// the image means agree within the independent renders' spread (no bias).
#[test]
fn sobol_has_less_error_at_16_spp_and_converges_to_the_same_image() {
    let reference = render_area_lit("independent", 4096, 100);
    let error = |sampler: &str| -> f64 {
        (0..4)
            .map(|seed| rel_rmse(&render_area_lit(sampler, 16, seed), &reference))
            .sum::<f64>()
            / 4.0
    };
    let independent = error("independent");
    let sobol = error("sobol");
    let stratified = error("stratified");
    eprintln!(
        "relative RMSE at 16 spp: independent {independent:.4}, stratified {stratified:.4}, sobol {sobol:.4}"
    );
    assert!(
        sobol < 0.8 * independent,
        "sobol {sobol} vs independent {independent}"
    );
    assert!(
        stratified < 0.9 * independent,
        "stratified {stratified} vs independent {independent}"
    );

    let mean = |f: &foton_core::film::Film| -> f64 {
        let px = f.pixels();
        px.iter()
            .map(|p| p.x as f64 + p.y as f64 + p.z as f64)
            .sum::<f64>()
            / px.len() as f64
    };
    let runs: Vec<f64> = (0..6)
        .map(|s| mean(&render_area_lit("independent", 256, 10 + s)))
        .collect();
    let avg = runs.iter().sum::<f64>() / runs.len() as f64;
    let sd = (runs.iter().map(|r| (r - avg).powi(2)).sum::<f64>() / (runs.len() - 1) as f64).sqrt();
    for sampler in ["sobol", "stratified"] {
        let m = mean(&render_area_lit(sampler, 256, 20));
        // One render's mean against the mean of six: within 5 standard deviations, plus 0.2 %
        // for the spread's own uncertainty with six runs.
        assert!(
            (m - avg).abs() < 5.0 * sd * (1.0 + 1.0 / 6.0f64).sqrt() + 2e-3 * avg,
            "{sampler}: image mean {m} vs independent {avg} +- {sd}"
        );
    }
}

/// A misspelt sampler is refused with the file, the key, the nearest name and the list;
/// `jitter` on a sampler that has none is refused; `foton compare` checks its NAME:SAMPLER.
#[test]
fn unknown_samplers_are_refused_with_a_suggestion() {
    let dir = foton_tests::temp_dir("samplers-bad");
    let path = foton_tests::write(
        &dir,
        "scene.toml",
        &(area_lit(4).replace("seed = 3", "seed = 3\nsampler = \"sobl\"")),
    );
    let error = |overrides: &[String]| match foton_loader::load(&path, overrides) {
        Ok(_) => panic!("loaded with {overrides:?}"),
        Err(e) => e.to_string(),
    };
    let e = error(&[]);
    for want in [
        "scene.toml:6",
        "render.sampler",
        "\"sobl\" (did you mean \"sobol\"?)",
        "independent, stratified, sobol",
    ] {
        assert!(e.contains(want), "{want:?} not in {e}");
    }
    let e = error(&[
        "render.sampler=\"sobol\"".into(),
        "render.jitter=false".into(),
    ]);
    assert!(
        e.contains("render.jitter") && e.contains("\"stratified\" only"),
        "{e}"
    );
    let scene = path.to_str().unwrap();
    let run = foton_tests::foton_with_plugins(&["compare", scene, "--integrators", "path:sobl"]);
    assert_ne!(run.code, 0);
    assert!(
        run.stderr.contains("did you mean \"sobol\""),
        "{}",
        run.stderr
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A TOML scene that names no sampler renders with `sobol` (the default: less error at equal
/// time, measured in docs/PERFORMANCE.md), and `foton check` says which sampler renders.
#[test]
fn sobol_is_the_toml_default_and_check_names_it() {
    let scene = foton_tests::repo_root().join("scenes/cornell-box.toml");
    let text = std::fs::read_to_string(&scene).unwrap();
    assert!(!text.contains("sampler"), "the scene must not name one");
    let scene = scene.to_str().unwrap();
    let run = foton_tests::foton_with_plugins(&["check", scene]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(run.stdout.contains("64 spp (sobol)"), "{}", run.stdout);
    let set = "render.sampler=\"independent\"";
    let run = foton_tests::foton_with_plugins(&["check", scene, "--set", set]);
    assert!(
        run.stdout.contains("64 spp (independent)"),
        "{}",
        run.stdout
    );
}

/// The table of samplers is what `[render] sampler` accepts and what the error for an
/// unknown name lists: each name loads a scene whose sampler has that name and whose every
/// number is in [0, 1), the names are those of `SamplerKind::NAMES`, and docs/scene-format.md
/// lists them in the `sampler` row of `[render]`.
#[test]
fn the_table_of_samplers_is_what_scenes_name() {
    let names: Vec<&str> = SAMPLERS.iter().map(|f| f.name).collect();
    assert_eq!(names, SamplerKind::NAMES);
    let dir = foton_tests::temp_dir("samplers-table");
    let path = foton_tests::write(&dir, "scene.toml", &area_lit(4));
    for name in &names {
        let set = format!("render.sampler={name:?}");
        let scene = foton_loader::load(&path, &[set]).unwrap_or_else(|e| panic!("{name}: {e}"));
        let kind = scene.render().sampler;
        assert_eq!(kind.name(), *name);
        for (px, index) in [(0u64, 0u32), (5, 3), (1 << 40, 17)] {
            let mut s = Sampler::new(kind, 9, px, index, 4);
            for d in 0..100 {
                let (u, v) = (s.next_f32(), s.next_2d());
                for x in [u, v.x, v.y] {
                    assert!((0.0..1.0).contains(&x), "{name}: draw {d} is {x}");
                }
            }
        }
    }
    let e = match foton_loader::load(&path, &["render.sampler=\"nope\"".into()]) {
        Ok(_) => panic!("an unknown sampler loaded"),
        Err(e) => e.to_string(),
    };
    assert!(
        e.contains(&format!("expected one of: {}", names.join(", "))),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);

    let doc = foton_tests::repo_root().join("docs/scene-format.md");
    let text = std::fs::read_to_string(doc).unwrap();
    let row = text
        .lines()
        .find(|l| l.starts_with("| `sampler`"))
        .expect("a `sampler` row in docs/scene-format.md");
    let listed: Vec<String> = names.iter().map(|n| format!("{n:?}")).collect();
    let listed = format!("| `{}` |", listed.join("`, `"));
    assert!(row.contains(&listed), "{row} should list {listed}");
}
