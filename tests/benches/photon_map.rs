//! Photon-map benchmark: build time and k-nearest-neighbour queries per second on 1M photons
//! at k = 50, for foton's hand-written kd-tree and kiddo's ImmutableKdTree, on a realistic
//! photon distribution (photons on the walls and spheres of a Cornell box, many coplanar).
//!
//!   cargo bench -p foton-tests --features kiddo --bench photon_map

use foton_core::sampling::{Rng, uniform_sphere};
use foton_photonmap::map::{Photon, PhotonMap};
use glam::Vec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use std::num::NonZeroUsize;
use std::time::Instant;

/// Points on the five walls of the box [-1,1] x [0,2] x [-1,1] and on two spheres.
fn cornell_points(n: usize, seed: u64) -> Vec<Vec3> {
    let mut rng = Rng::new(&[seed]);
    (0..n)
        .map(|_| {
            let (a, b) = (rng.next_f32() * 2.0 - 1.0, rng.next_f32() * 2.0);
            match rng.next_u32() % 7 {
                0 => Vec3::new(a, 0.0, b - 1.0),
                1 => Vec3::new(a, 2.0, b - 1.0),
                2 => Vec3::new(a, b, -1.0),
                3 => Vec3::new(-1.0, b, a),
                4 => Vec3::new(1.0, b, a),
                5 => Vec3::new(-0.45, 0.35, -0.35) + 0.35 * uniform_sphere(rng.next_2d()),
                _ => Vec3::new(0.45, 0.3, 0.25) + 0.3 * uniform_sphere(rng.next_2d()),
            }
        })
        .collect()
}

fn main() {
    let n = 1_000_000;
    let k = 50;
    let queries = 200_000;
    let max_radius = 0.5f32;
    let points = cornell_points(n, 1);
    let query_points = cornell_points(queries, 2);
    let photons: Vec<Photon> = points
        .iter()
        .map(|&p| Photon::new(p, Vec3::ONE, Vec3::Y, Vec3::Y))
        .collect();
    println!("{n} photons on Cornell-box surfaces, k = {k}, {queries} queries, 1 thread");

    // foton's kd-tree
    let t = Instant::now();
    let map = PhotonMap::build(photons);
    let build = t.elapsed().as_secs_f64();
    let mut out = Vec::new();
    let t = Instant::now();
    let mut checksum = 0.0f64;
    for q in &query_points {
        checksum += map.knn(*q, k, max_radius, |_, _| true, &mut out) as f64;
    }
    let secs = t.elapsed().as_secs_f64();
    println!(
        "foton kd-tree:        build {:.3} s ({} threads), {:.0} queries/s per thread (checksum {checksum:.3})",
        build,
        rayon::current_num_threads(),
        queries as f64 / secs
    );

    // kiddo
    let raw: Vec<[f32; 3]> = points.iter().map(|p| p.to_array()).collect();
    let t = Instant::now();
    let tree: ImmutableKdTree<f32, 3> = ImmutableKdTree::new_from_slice_parallel(&raw).unwrap();
    let build = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut checksum = 0.0f64;
    let kk = NonZeroUsize::new(k).unwrap();
    for q in &query_points {
        let found = tree
            .query(&q.to_array())
            .nearest_n::<SquaredEuclidean<f32>>(kk)
            .within(max_radius * max_radius)
            .unsorted()
            .execute();
        checksum += found.iter().map(|r| r.distance).fold(0.0f32, f32::max) as f64;
    }
    let secs = t.elapsed().as_secs_f64();
    println!(
        "kiddo ImmutableKdTree: build {:.3} s, {:.0} queries/s per thread (checksum {checksum:.3})",
        build,
        queries as f64 / secs
    );
}
