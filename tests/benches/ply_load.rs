//! Loading a large binary PLY mesh (a benchmark, not a test): a 708x708 grid bent into a
//! sphere, 1,002,528 triangles, written as binary little-endian with normals and uv (as
//! scanners and exporters write them). Prints the seconds of the parse alone (bytes to
//! positions and triangles) and of `Scene::load` (read, parse, transform, closedness, BVH).
//!
//!   cargo bench -p foton-tests --bench ply_load

use foton_core::accel::Accel;
use foton_core::geometry::Primitive;
use foton_core::scene::Scene;
use foton_core::scene::mesh::is_closed;
use foton_core::scene::ply;
use foton_tests::{temp_dir, write};
use glam::Vec3;
use std::f32::consts::PI;
use std::time::Instant;

/// Vertices per side of the grid; (N - 1)^2 quads of two triangles.
const N: usize = 709;

fn sphere_ply() -> Vec<u8> {
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        N * N,
        2 * (N - 1) * (N - 1)
    )
    .into_bytes();
    for i in 0..N {
        for j in 0..N {
            let (u, v) = (i as f32 / (N - 1) as f32, j as f32 / (N - 1) as f32);
            // Latitude strictly inside the poles, so that no triangle is degenerate.
            let (theta, phi) = (0.05 + 0.9 * PI * v, 2.0 * PI * u);
            let n = [
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            ];
            for x in n.iter().chain(&n).chain(&[u, v]) {
                out.extend_from_slice(&x.to_le_bytes());
            }
        }
    }
    for i in 0..N - 1 {
        for j in 0..N - 1 {
            let a = (i * N + j) as i32;
            let (b, c, d) = (a + N as i32, a + N as i32 + 1, a + 1);
            for tri in [[a, b, c], [a, c, d]] {
                out.push(3);
                for k in tri {
                    out.extend_from_slice(&k.to_le_bytes());
                }
            }
        }
    }
    out
}

fn main() {
    let bytes = sphere_ply();
    let dir = temp_dir("ply-bench");
    let mesh = dir.join("sphere.ply");
    std::fs::write(&mesh, &bytes).unwrap();
    println!(
        "binary PLY: {:.1} MB, {} vertices, {} triangles",
        bytes.len() as f64 / 1e6,
        N * N,
        2 * (N - 1) * (N - 1)
    );

    let start = Instant::now();
    let raw = ply::parse(&bytes).unwrap();
    let parse = start.elapsed().as_secs_f64();
    assert_eq!(raw.triangles.len(), 2 * (N - 1) * (N - 1));
    println!("parse:              {parse:.3} s");

    let scene = write(
        &dir,
        "scene.toml",
        r#"
[render]
integrator = "path"
[film]
width = 16
height = 16
[camera]
position = [0, 0, 4]
look_at = [0, 0, 0]
fov = 40
[materials.white]
type = "diffuse"
reflectance = [0.5, 0.5, 0.5]
[[shapes]]
type = "mesh"
file = "sphere.ply"
material = "white"
[[lights]]
type = "point"
position = [0, 3, 3]
intensity = [1, 1, 1]
"#,
    );
    let start = Instant::now();
    let loaded = Scene::load(&scene, &[]).unwrap();
    let load = start.elapsed().as_secs_f64();
    assert_eq!(loaded.accel.primitives().len(), 2 * (N - 1) * (N - 1));
    println!("Scene::load + BVH:  {load:.3} s");

    // Where the load's time goes: the two largest parts, timed alone.
    let corners: Vec<[Vec3; 3]> = raw
        .triangles
        .iter()
        .map(|t| t.map(|i| raw.positions[i as usize]))
        .collect();
    let start = Instant::now();
    assert!(!is_closed(&corners), "the sphere is open at its poles");
    println!(
        "  of which is_closed: {:.3} s",
        start.elapsed().as_secs_f64()
    );
    let prims: Vec<Primitive> = loaded.accel.primitives().to_vec();
    let start = Instant::now();
    let accel = Accel::build(prims);
    println!(
        "  of which BVH build: {:.3} s",
        start.elapsed().as_secs_f64()
    );
    assert_eq!(accel.primitives().len(), loaded.accel.primitives().len());
    let _ = std::fs::remove_dir_all(&dir);
}
