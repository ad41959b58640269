//! What the tests of single materials share: the BSDF a material gives on a quad, and the
//! chi-square test of that BSDF's sampling.

use crate::sampling::{SphereGrid, check_directions, d};
use foton_core::api::{Ray, TransportMode, Vec3};
use foton_core::bsdf::Bsdf;
use foton_core::sampling::Rng;
use foton_tests::header;
use std::path::Path;

/// The BSDF at a point near the centre of a 4 x 4 quad facing +z (dp/du = 4 x, dp/dv = 4 y)
/// of material `m` (a TOML table body), the scene written into `dir` (where the material's
/// textures may lie).
pub(crate) fn quad_bsdf_in(dir: &Path, m: &str) -> Bsdf {
    let toml = header("path", 1, 1, 4, 4)
        + &format!(
            r#"
[camera]
position = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 30.0

[materials.m]
{m}

[[lights]]
type = "point"
position = [0.0, 0.0, 3.0]
intensity = [1.0, 1.0, 1.0]

[[shapes]]
type = "quad"
origin = [-2.0, -2.0, 0.0]
u = [4.0, 0.0, 0.0]
v = [0.0, 4.0, 0.0]
material = "m"
"#
        );
    let file = foton_tests::write(dir, "quad.toml", &toml);
    let scene = foton_loader::load(&file, &[]).unwrap();
    let hit = scene
        .intersect(&Ray::new(Vec3::new(0.1, 0.2, 1.0), -Vec3::Z), f32::INFINITY)
        .unwrap();
    scene.bsdf(&hit).unwrap()
}

/// [`quad_bsdf_in`] a new temporary folder.
pub(crate) fn quad_bsdf(name: &str, m: &str) -> Bsdf {
    quad_bsdf_in(&foton_tests::temp_dir(name), m)
}

/// Chi-square of `bsdf`'s radiance sampling for `wo` against its pdf over the sphere around
/// `axis` (400 000 samples): delta samples (mirror reflections) and directions that carry
/// nothing are the "no direction" class, expected with 1 - the pdf's integral over the grid;
/// every other sample's weight must be f cos / pdf. Returns the share of delta samples.
pub(crate) fn check_lobe_sampling(
    label: &str,
    bsdf: &Bsdf,
    wo: Vec3,
    axis: Vec3,
    seed: &[u64],
) -> f64 {
    let n = 400_000;
    let grid = SphereGrid::full_sphere(d(axis), 20, 20);
    let pdf = |w: glam::DVec3| bsdf.pdf(wo, w.as_vec3()) as f64;
    let p_none =
        (1.0 - grid.probabilities(&pdf).iter().sum::<f64>()).max(crate::sampling::P_HORIZON);
    let mut rng = Rng::new(seed);
    let mut deltas = 0u32;
    check_directions(label, &grid, n, p_none, &pdf, &mut || {
        let s = bsdf.sample(wo, rng.next_2d(), rng.next_f32(), TransportMode::Radiance)?;
        if s.delta {
            deltas += 1;
            return None;
        }
        let want = bsdf.eval(wo, s.wi) / s.pdf;
        assert!(
            (s.weight - want).abs().max_element() <= 1e-3 * want.max_element().max(1e-3),
            "{label}: weight {} against f cos / pdf {want}",
            s.weight
        );
        Some(d(s.wi))
    });
    deltas as f64 / n as f64
}
