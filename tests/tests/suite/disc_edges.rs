//! The surface estimate at a wall: the k-nearest disc of a floor point beside a wall reaches
//! behind the wall, where no floor photon can land. Divided by the whole disc, the estimate
//! halves on the crease and quarters in a corner; clipped at the walls the probes find
//! (`DiscClip`), it must give the floor's own density there, and change nothing away from
//! the walls.

use foton_core::Rgb;
use foton_core::kernel::{BoxKernel, ConeKernel, NormalizedKernel};
use foton_core::sampling::Rng;
use foton_core::scene::Scene;
use foton_photonmap::map::{Disc, DiscClip, Estimate, Photon, PhotonMap};
use foton_tests::{temp_dir, write};
use glam::Vec3;

/// Photons per unit area on the floor and on the walls.
const DENSITY: f32 = 100_000.0;
/// Photons per estimate: 49 summed, so one estimate's relative noise is about 1/7.
const K: usize = 50;

/// The closed box [-1, 1]^3 of the photon tests (its floor y = -1, walls at x, z = +-1).
fn scene() -> Scene {
    let dir = temp_dir("disc_edges");
    let toml = foton_tests::closed_box(
        "photon",
        8,
        0.5,
        0.0,
        "[[lights]]\ntype = \"point\"\nposition = [0.0, 0.0, 0.0]\npower = [1.0, 1.0, 1.0]\n",
    );
    let path = write(&dir, "scene.toml", &toml);
    let scene = foton_loader::load(&path, &[]).unwrap();
    let _ = std::fs::remove_dir_all(dir);
    scene
}

/// Uniform random photons of flux 1 on the floor and on the wall x = -1 (its own normal), so
/// that the irradiance the floor's photons give is DENSITY everywhere on it.
fn photons() -> PhotonMap {
    let mut rng = Rng::new(&[20]);
    let n = (DENSITY * 4.0) as usize;
    let mut photons = Vec::with_capacity(2 * n);
    for _ in 0..n {
        let (a, b) = (rng.next_f32() * 2.0 - 1.0, rng.next_f32() * 2.0 - 1.0);
        photons.push(Photon::new(
            Vec3::new(a, -1.0, b),
            Rgb::ONE,
            Vec3::Y,
            Vec3::Y,
        ));
        let (a, b) = (rng.next_f32() * 2.0 - 1.0, rng.next_f32() * 2.0 - 1.0);
        photons.push(Photon::new(
            Vec3::new(-1.0, a, b),
            Rgb::ONE,
            Vec3::X,
            Vec3::X,
        ));
    }
    PhotonMap::build(photons)
}

/// The floor's irradiance estimate at `p` over DENSITY, with the disc clipped or not.
fn estimate(scene: &Scene, map: &PhotonMap, kernel: &NormalizedKernel, p: Vec3, clip: bool) -> f32 {
    let estimate = Estimate {
        k: K,
        max_radius: 0.2,
        kernel,
    };
    let clip = if clip {
        DiscClip::probe(scene, p, Vec3::Y, estimate.max_radius)
    } else {
        DiscClip::NONE
    };
    let mut scratch = Vec::new();
    let disc = Disc::new(p, Vec3::Y, 16).clipped(&clip);
    let e = map.radiance(&disc, &estimate, &mut scratch, |_| Rgb::ONE);
    e.x / DENSITY
}

/// Points on the floor along the crease with the wall x = -1, a millimetre from it, 5 cm
/// apart (the estimates' radius is about 1.8 cm: their photons do not overlap).
fn along_the_crease() -> Vec<Vec3> {
    (0..37)
        .map(|i| Vec3::new(-0.999, -1.0, -0.9 + 0.05 * i as f32))
        .collect()
}

fn mean(xs: &[f32]) -> f32 {
    xs.iter().sum::<f32>() / xs.len() as f32
}

#[test]
fn the_disc_estimate_on_a_crease_gives_the_floors_density() {
    let (scene, map) = (scene(), photons());
    let kernel = NormalizedKernel::new(Box::new(BoxKernel)).unwrap();
    let points = along_the_crease();
    // One estimate's relative standard deviation is 1/sqrt(K - 2) (the k-th neighbour's
    // area is Gamma(K) distributed); the mean of 37 independent ones has 0.024: 4 sigma is
    // 0.1. Unclipped, the disc is half behind the wall: the mean is 1/2.
    let clipped: Vec<f32> = points
        .iter()
        .map(|&p| estimate(&scene, &map, &kernel, p, true))
        .collect();
    let unclipped: Vec<f32> = points
        .iter()
        .map(|&p| estimate(&scene, &map, &kernel, p, false))
        .collect();
    let sigma = 1.0 / ((K - 2) as f32).sqrt() / (points.len() as f32).sqrt();
    assert!(
        (mean(&clipped) - 1.0).abs() < 4.0 * sigma,
        "clipped at the wall: mean {} of the floor's density (4 sigma: {})",
        mean(&clipped),
        4.0 * sigma
    );
    assert!(
        (mean(&unclipped) - 0.5).abs() < 4.0 * sigma,
        "unclipped: mean {} (the half disc behind the wall is empty: 0.5 expected)",
        mean(&unclipped)
    );
}

#[test]
fn the_disc_estimate_in_the_corners_and_near_a_wall_gives_the_floors_density() {
    let (scene, map) = (scene(), photons());
    let kernel = NormalizedKernel::new(Box::new(BoxKernel)).unwrap();
    // The floor's four corners (a quarter of the disc on the floor) and points a little
    // under a radius from a wall (a segment of the disc behind it), 40 points in all.
    let mut points = Vec::new();
    for (sx, sz) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
        points.push(Vec3::new(sx * 0.999, -1.0, sz * 0.999));
    }
    for i in 0..36 {
        let (along, off) = (-0.85 + 0.05 * i as f32, 0.999 - 0.008 * (i % 3) as f32);
        points.push(match i % 4 {
            0 => Vec3::new(-off, -1.0, along),
            1 => Vec3::new(off, -1.0, along),
            2 => Vec3::new(along, -1.0, -off),
            _ => Vec3::new(along, -1.0, off),
        });
    }
    let clipped: Vec<f32> = points
        .iter()
        .map(|&p| estimate(&scene, &map, &kernel, p, true))
        .collect();
    let sigma = 1.0 / ((K - 2) as f32).sqrt() / (points.len() as f32).sqrt();
    assert!(
        (mean(&clipped) - 1.0).abs() < 4.0 * sigma,
        "near the walls: mean {} of the floor's density (4 sigma: {}); corners {:?}",
        mean(&clipped),
        4.0 * sigma,
        &clipped[..4]
    );
    // The corners alone: four estimates, 2 sigma each is 0.58 of one; unclipped they are a
    // quarter.
    let corners = mean(&clipped[..4]);
    assert!(
        (corners - 1.0).abs() < 2.0 / ((K - 2) as f32).sqrt(),
        "corners: {:?}",
        &clipped[..4]
    );
}

#[test]
fn the_clipped_cone_estimate_divides_by_the_kernels_mass_on_the_floor() {
    let (scene, map) = (scene(), photons());
    let kernel = NormalizedKernel::new(Box::new(ConeKernel { c: 1.0 })).unwrap();
    let points = along_the_crease();
    let clipped: Vec<f32> = points
        .iter()
        .map(|&p| estimate(&scene, &map, &kernel, p, true))
        .collect();
    // The cone weighs the photons near the centre more: a little noisier than the box.
    let sigma = 1.5 / ((K - 2) as f32).sqrt() / (points.len() as f32).sqrt();
    assert!(
        (mean(&clipped) - 1.0).abs() < 4.0 * sigma,
        "cone kernel at the wall: mean {}",
        mean(&clipped)
    );
}

#[test]
fn away_from_the_walls_the_clip_changes_nothing() {
    let (scene, map) = (scene(), photons());
    let kernel = NormalizedKernel::new(Box::new(BoxKernel)).unwrap();
    for i in 0..20 {
        let p = Vec3::new(-0.7 + 0.07 * i as f32, -1.0, 0.3 - 0.03 * i as f32);
        let (a, b) = (
            estimate(&scene, &map, &kernel, p, true),
            estimate(&scene, &map, &kernel, p, false),
        );
        assert_eq!(a.to_bits(), b.to_bits(), "at {p}: {a} clipped, {b} not");
    }
}
