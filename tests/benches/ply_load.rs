//! Loading a large binary PLY mesh (a benchmark, not a test): a 708x708 grid bent into a
//! sphere, 1,002,528 triangles, written as binary little-endian with normals and uv (as
//! scanners and exporters write them). Prints the seconds of the parse alone (bytes to
//! positions, triangles, normals and uv), of `foton_loader::load` (read, parse, transform,
//! BVH) and of its largest part, and of the closedness check that a mesh bounding a medium adds; then loads the same mesh written without normals
//! and uv, with and without `face_normals`, which shows what computing vertex normals costs.
//!
//!   cargo bench -p foton-tests --bench ply_load
//!
//! With FOTON_PLY_KEEP=1 the files stay where it prints, for other renderers to load
//! (tests/benches/ply_load_mitsuba.py times Mitsuba 3 on them).

use foton_core::accel::Accel;
use foton_core::geometry::Primitive;
use foton_core::scene::Scene;
use foton_loader::mesh::is_closed;
use foton_loader::ply;
use foton_tests::{temp_dir, write};
use glam::Vec3;
use std::f32::consts::PI;
use std::path::Path;
use std::time::Instant;

/// Vertices per side of the grid; (N - 1)^2 quads of two triangles.
const N: usize = 709;

/// The sphere as a binary PLY; `attributes`: with normals and uv.
fn sphere_ply(attributes: bool) -> Vec<u8> {
    let extra = if attributes {
        "property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n"
    } else {
        ""
    };
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n{extra}element face {}\nproperty list uchar int vertex_indices\nend_header\n",
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
            let uv = [u, v];
            let attrs = if attributes { &n[..] } else { &[] };
            let uv = if attributes { &uv[..] } else { &[] };
            for x in n.iter().chain(attrs).chain(uv) {
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

/// A scene of the mesh file `mesh` (in the scene's folder) alone.
fn scene_toml(mesh: &str, face_normals: bool) -> String {
    format!(
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
file = "{mesh}"
material = "white"
face_normals = {face_normals}
[[lights]]
type = "point"
position = [0, 3, 3]
intensity = [1, 1, 1]
"#
    )
}

/// `foton_loader::load` of `scene`, and its seconds.
fn load(scene: &Path) -> (Scene, f64) {
    let start = Instant::now();
    let loaded = foton_loader::load(scene, &[]).unwrap();
    let seconds = start.elapsed().as_secs_f64();
    assert_eq!(loaded.accel().primitives().len(), 2 * (N - 1) * (N - 1));
    (loaded, seconds)
}

fn main() {
    let keep = std::env::var_os("FOTON_PLY_KEEP").is_some();
    let bytes = sphere_ply(true);
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

    let (loaded, total) = load(&write(&dir, "scene.toml", &scene_toml("sphere.ply", false)));
    println!("loader::load + BVH:{total:.3} s");

    // Where the load's time goes: the two largest parts, timed alone.
    let corners: Vec<[Vec3; 3]> = raw
        .triangles
        .iter()
        .map(|t| t.map(|i| raw.positions[i as usize]))
        .collect();
    let start = Instant::now();
    assert!(!is_closed(&corners), "the sphere is open at its poles");
    let closed = start.elapsed().as_secs_f64();
    // The loader asks it only of meshes that may bound a medium; not of this diffuse one.
    println!(
        "is_closed (not in this load: only for shapes that may bound a medium): {closed:.3} s"
    );
    let prims: Vec<Primitive> = loaded.accel().primitives().to_vec();
    drop(loaded);
    let start = Instant::now();
    let accel = Accel::build(prims);
    let bvh = start.elapsed().as_secs_f64();
    println!("  of which BVH build: {bvh:.3} s");
    println!(
        "  the rest (read, parse, transform, attributes): {:.3} s",
        total - bvh
    );
    drop(accel);

    // Without normals in the file the loader computes them, unless face_normals.
    let plain = sphere_ply(false);
    std::fs::write(dir.join("sphere-plain.ply"), &plain).unwrap();
    let (_, computed) = load(&write(
        &dir,
        "plain.toml",
        &scene_toml("sphere-plain.ply", false),
    ));
    let (_, faceted) = load(&write(
        &dir,
        "plain-faceted.toml",
        &scene_toml("sphere-plain.ply", true),
    ));
    println!(
        "without normals and uv ({:.1} MB): load {computed:.3} s, with face_normals {faceted:.3} s",
        plain.len() as f64 / 1e6
    );

    if keep {
        println!("kept: {} and sphere-plain.ply", mesh.display());
    } else {
        let _ = std::fs::remove_dir_all(&dir);
    }
}
